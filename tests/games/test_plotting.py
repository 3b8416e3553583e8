"""Figures of a receding-horizon run (paths, obstacle, look-ahead) and its GIF; an open-loop game
falls back to the trajectory plots."""

from __future__ import annotations

from PIL import Image

from gamespec.loader import load
from gamespec.plotting import plot_result
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS
from tests.games.test_lq_game import FILE


def test_receding_horizon_figures_and_gif(tmp_path):
    spec = load(PROBLEMS / "ch7" / "asymmetric_obstacle.yaml", ["receding_horizon.time_limit=0.3"])
    result = compile_spec(spec).solve()
    paths = plot_result(result, tmp_path, animate=True)
    names = {p.name for p in paths}
    assert names == {"asymmetric_obstacle_paths.png", "asymmetric_obstacle.gif"}
    with Image.open(tmp_path / "asymmetric_obstacle.gif") as gif:
        last = result.control_time[-1] < result.time[-1]
        assert gif.n_frames == result.metrics["steps"] + last, "a frame per step and one at the end"


def test_open_loop_game_gets_trajectory_plots(tmp_path):
    result = compile_spec(load(FILE)).solve()
    assert all(p.exists() for p in plot_result(result, tmp_path))
