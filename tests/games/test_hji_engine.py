"""The ``hji`` backend's hj_reachability engine (``solver.options.hji.engine: hj_reachability``,
the optional ``hj`` extra) against the same closed forms as the project's engine, and the two
engines against each other; skipped where hj_reachability is not installed.

- The box game of ``tests/games/test_capture_time.py`` as a game of degree: the minimum time to
  capture at every node within a grid spacing at the slowest guaranteed speed (1/2) of
  ``hypot((|x| − τ/2)⁺, (|y| − τ)⁺) = r``, on both engines; the two captured sets agree wherever
  the exact edge is more than a spacing away.
- The reach–avoid box game of ``tests/games/test_hji.py`` (a wall the pursuer must not enter): the
  captured set on the near side of the wall only.
"""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

from gamespec.errors import UnsupportedFeature
from gamespec.loader import load
from gamespec.result import Status
from gamespec.solving import compile_spec
from tests.games.test_capture_time import BOX_GAME, box_capture_time
from tests.games.test_hji import REACH_AVOID


def test_without_jax_the_engine_is_refused_with_the_reason(tmp_path, monkeypatch):
    import gamespec_levelset.hji_jax as engine

    monkeypatch.setattr(engine, "available", lambda: "the hj_reachability engine needs the hj extra")
    file = tmp_path / "box.yaml"
    file.write_text(textwrap.dedent(BOX_GAME.format(nodes=41)))
    with pytest.raises(UnsupportedFeature, match="hj extra"):
        compile_spec(load(file, ["solver.options.hji.engine=hj_reachability"]))


def test_both_engines_give_the_closed_form_capture_time(tmp_path):
    pytest.importorskip("hj_reachability")
    file = tmp_path / "box.yaml"
    file.write_text(textwrap.dedent(BOX_GAME.format(nodes=41)))
    results = {
        engine: compile_spec(load(file, [f"solver.options.hji.engine={engine}"])).solve()
        for engine in ("gamespec", "hj_reachability")
    }
    gx, gy = np.meshgrid(
        results["gamespec"].arrays["grid_x"], results["gamespec"].arrays["grid_y"], indexing="ij"
    )
    spacing = gx[1, 0] - gx[0, 0]
    exact = box_capture_time(gx, gy)
    within = exact <= 0.45
    for result in results.values():
        assert np.abs(result.arrays["capture_time"][within] - exact[within]).max() <= spacing / 0.5
        assert result.metrics["outcome"] == "capture"
        assert abs(result.objective - box_capture_time(np.array(0.4), np.array(0.3))) <= spacing / 0.5
    clear = np.abs(exact - 0.5) > spacing / 0.5 * (1 + 1e-9)
    captured = [r.arrays["value"] <= 0 for r in results.values()]
    assert np.array_equal(captured[0][clear], captured[1][clear])


@pytest.mark.slow
def test_hj_reachability_reach_avoid_stops_at_the_wall(tmp_path):
    pytest.importorskip("hj_reachability")
    file = tmp_path / "wall.yaml"
    file.write_text(textwrap.dedent(REACH_AVOID.format(x="a + c", c_lower=-0.5)))
    result = compile_spec(load(file, ["solver.options.hji.engine=hj_reachability"])).solve()
    gx, gy = np.meshgrid(result.arrays["grid_x"], result.arrays["grid_y"], indexing="ij")
    outside = np.hypot(np.maximum(abs(gx) - 0.5, 0), np.maximum(abs(gy) - 0.5, 0))
    reached = outside <= 0.3
    spacing = (gx[1, 0] - gx[0, 0]) * (1 + 1e-9)
    clear = (abs(outside - 0.3) > spacing) & ((abs(gx - 0.4) > spacing) | ~reached)
    assert np.array_equal((result.arrays["value"] <= 0)[clear], (reached & (gx < 0.4))[clear])
    assert result.status in (Status.OPTIMAL, Status.FEASIBLE)
