"""The chapter 6 figures are drawn from Results and from a sweep folder's rows."""

from __future__ import annotations

import pytest

from gamespec.desensitize.plotting import plot_desensitized, plot_tradeoff
from gamespec.errors import GamespecError
from gamespec.studies.store import ResultStore
from tests.desensitize.helpers import FINAL, TRAJECTORY, file_solver


def test_bundle_and_sensitivity_figures(tmp_path) -> None:
    result = file_solver(TRAJECTORY, edit={"monte_carlo": {"samples": 60, "tracking": True}}).solve()
    paths = plot_desensitized(result, tmp_path)
    assert [p.name for p in paths] == [
        "zermelo_trajectory_desensitized_monte_carlo.png",
        "zermelo_trajectory_desensitized_sensitivity.png",
    ]
    assert all(p.stat().st_size > 0 for p in paths)


def test_tradeoff_from_a_sweep_folder(tmp_path) -> None:
    solver = file_solver(FINAL, edit={"monte_carlo": {"samples": 0}})
    store = ResultStore(tmp_path)
    for alpha in (0.0, 25.0, 75.0):
        result = solver.solve({"alpha": alpha})
        store.put(f"alpha={alpha}", {"alpha": alpha, **result.summary(), "metrics": result.metrics})
    (path,) = plot_tradeoff(store.items().values(), tmp_path / "figures", "alpha")
    assert path.name == "tradeoff.png" and path.stat().st_size > 0
    with pytest.raises(GamespecError, match="no solved desensitized points"):
        plot_tradeoff([{"alpha": 1.0, "metrics": {}}], tmp_path, "alpha")
