"""The engagement plotter writes its figures from a saved Result alone."""

from __future__ import annotations

import matplotlib
import pytest

import gamespec
from gamespec.pursuit import plotting as engagement_plots
from tests.conftest import PROBLEMS


@pytest.mark.parametrize(
    ("name", "backend", "expected"),
    [
        ("ch2/constant_bearing_two_on_one.yaml", "analytic", {"paths.png", "regions.png", "distances.png"}),
        ("ch2/relay_constant_bearing.yaml", None, {"paths.png", "regions.png", "distances.png", "paths.gif"}),
        ("ch3/mpse_optimal_evasion_cb.yaml", "analytic", {"paths.png", "distances.png"}),
    ],
)
def test_plot_from_a_saved_result(
    cli, tmp_path, monkeypatch, name: str, backend: str | None, expected: set[str]
) -> None:
    """The files; an animation of few frames at a low resolution (what one shows: tests/plots)."""
    monkeypatch.setattr(engagement_plots, "FRAMES", 8)
    monkeypatch.setitem(matplotlib.rcParams, "savefig.dpi", 20)
    result = gamespec.solve(PROBLEMS / name, backend)
    result.save(tmp_path / "run")
    args = ["plot", tmp_path / "run", "--out", tmp_path / "figs"]
    code, _, err = cli(*args, *(["--animate"] if "paths.gif" in expected else []))
    assert code == 0, err
    assert {p.name for p in (tmp_path / "figs").iterdir()} == expected
