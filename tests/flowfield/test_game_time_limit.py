"""The covariance-game stage honours ``max_wall_time`` (issue 27, item 2): it takes what the
reachability stage left of it (``problem.nominal.wall_time``), and past it the best responses, the
lower value and the Monte Carlo stop, the Result ``time_limit`` naming what was cut short."""

from __future__ import annotations

import copy
import time

from gamespec.flowfield.stages import covariance_game_spec, reachability_spec
from gamespec.loader import spec_from_dict
from gamespec.result import Status
from gamespec.solving import solve
from tests.flowfield.test_stages import _spec


def _stages(max_wall_time: float):
    """The cheap chain of ``test_stages`` with a small Monte Carlo: stage 1 solved without a limit,
    and the flow game with the limit ``max_wall_time``."""
    data = _spec()
    data["method"]["monte_carlo"]["samples"] = 200
    reach = solve(reachability_spec(spec_from_dict(data)))
    assert "capture_time" in reach.metrics, reach.message
    limited = copy.deepcopy(data)
    limited["solver"]["options"]["levelset"]["max_wall_time"] = max_wall_time
    return spec_from_dict(limited), reach


def test_a_tiny_limit_stops_the_covariance_game_with_the_status_time_limit() -> None:
    spec, reach = _stages(1e-9)
    game = covariance_game_spec(spec, reach)
    assert game.problem.nominal is not None
    assert game.problem.nominal.wall_time == reach.solve_time_s > 0
    start = time.process_time()
    result = solve(game)
    used = time.process_time() - start
    assert result.status is Status.TIME_LIMIT
    assert "max_wall_time" in result.message
    assert "covariance game, best responses after 1 iterations" in result.message
    assert "Monte Carlo, open_loop not simulated" in result.message
    assert result.metrics["best_response"]["outcome"] == "time_limit"
    assert result.metrics["monte_carlo_capture_probability"] == {}
    assert used < 10.0


def test_the_game_takes_only_what_the_reachability_stage_left() -> None:
    """A limit of 100 s after a stage that (by its record) took 100 s leaves nothing; the same limit
    with the stage's true (sub-second) time leaves the whole game to run."""
    spec, reach = _stages(100.0)
    game = covariance_game_spec(spec, reach)
    assert game.problem.nominal is not None
    spent = game.model_copy(
        update={
            "problem": game.problem.model_copy(
                update={"nominal": game.problem.nominal.model_copy(update={"wall_time": 100.0})}
            )
        }
    )
    assert solve(spent).status is Status.TIME_LIMIT
    full = solve(game)
    assert full.status is not Status.TIME_LIMIT, full.message
    assert set(full.metrics["monte_carlo_capture_probability"]) == {"open_loop", "closed_loop"}
