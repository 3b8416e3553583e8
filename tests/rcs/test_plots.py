"""Fig. 6.6's map against eqs. 6.40/6.42, and the figures the plotters write."""

import numpy as np
import pytest

from gamespec.rcs.plotting import plot_levels, plot_rcs, plot_sensitivity_map, sensitivity_map
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS


@pytest.mark.parametrize("beta", [0.5, 1.0, 2.0, 4.0])
def test_map_is_eq_6_42(beta):
    t, c, z = 1.0, 0.0, 1.0
    X, Y, G, Sg, Sr = sensitivity_map(center=(c, z), radius=0.6, t=t, power=beta, points=41)
    D2 = (X - c) ** 2 + (Y - z) ** 2
    expected = np.abs(beta * (Y - z) * t * D2 ** (beta / 2 - 1))
    np.testing.assert_allclose(Sg, expected, rtol=1e-10, atol=1e-12)
    s = 1 / (1 + np.exp(-np.minimum(G, 0)))
    np.testing.assert_allclose(Sr, s * (1 - s) * expected, rtol=1e-10, atol=1e-12)


def test_figures(tmp_path):
    solver = compile_spec(PROBLEMS / "ch6" / "rcs_single_obstacle.yaml", options={"warm_start": False})
    results = [solver.solve(parameters={"problem.parameters.Q": q}) for q in (0.0, 1.0)]
    written = plot_rcs(results[1], tmp_path)
    assert {p.name.split("rcs_single_obstacle_")[1] for p in written} == {
        "obstacles.png",
        "rcs.png",
        "sensitivity_map.png",
    }
    assert plot_levels(results, ["Q = 0", "Q = 1"], tmp_path / "levels.png").stat().st_size > 0
    assert plot_levels(results, ["Q = 0", "Q = 1"], tmp_path / "u.png", control="u").stat().st_size > 0
    assert plot_sensitivity_map(tmp_path / "fig_6_6.png").stat().st_size > 0
