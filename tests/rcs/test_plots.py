"""Fig. 6.6's map against eqs. 6.40/6.42, and the figures the plotters write."""

import numpy as np
import pytest

from gamespec.rcs.plotting import plot_levels, plot_rcs, plot_sensitivity_map, sensitivity_map
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS
from tests.plots.recording import legend_texts, recording


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
    """The RCS figures show what they are given: each weight level's path (Figs. 6.7(a), 6.8) and
    control (Fig. 6.9(b)) under its label, and Fig. 6.6's |S_g| and |S_r| maps with the infeasible
    disc left out."""
    solver = compile_spec(PROBLEMS / "ch6" / "rcs_single_obstacle.yaml", options={"warm_start": False})
    results = [solver.solve(parameters={"problem.parameters.Q": q}) for q in (0.0, 1.0)]
    labels = ["Q = 0", "Q = 1"]
    with recording() as saved:
        written = plot_rcs(results[1], tmp_path)
        plot_levels(results, labels, tmp_path / "levels.png")
        plot_levels(results, labels, tmp_path / "u.png", control="u")
        plot_sensitivity_map(tmp_path / "fig_6_6.png")
    assert {p.name.split("rcs_single_obstacle_")[1] for p in written} == {
        "obstacles.png",
        "rcs.png",
        "sensitivity_map.png",
    }
    figures = {figure.name: figure for figure in saved}
    (paths,) = figures["levels.png"].axes
    (controls,) = figures["u.png"].axes
    assert legend_texts(paths) == labels and legend_texts(controls) == labels
    for result, label in zip(results, labels, strict=True):
        (path,) = [line for line in paths.lines if line.get_label() == label]
        np.testing.assert_array_equal(path.get_xdata(), result.states["x"])
        np.testing.assert_array_equal(path.get_ydata(), result.states["y"])
        (control,) = [line for line in controls.lines if line.get_label() == label]
        np.testing.assert_array_equal(control.get_ydata(), result.controls["u"])
    assert (controls.get_xlabel(), controls.get_ylabel()) == ("t", "u")
    _, _, G, Sg, Sr = sensitivity_map()
    maps = figures["fig_6_6.png"].axes[:2]
    for ax, title, values in zip(maps, ("|S_g|", "|S_r|"), (Sg, Sr), strict=True):
        assert ax.get_title() == title
        (mesh,) = ax.collections
        shown = np.ma.asarray(mesh.get_array()).reshape(G.shape)
        np.testing.assert_array_equal(np.ma.getmaskarray(shown), G > 0)
        np.testing.assert_array_equal(shown.compressed(), values[G <= 0])
