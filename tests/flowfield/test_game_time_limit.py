"""The covariance-game stage honours ``max_wall_time`` (issue 27, item 2): it takes what the
reachability stage left of it (``problem.nominal.wall_time``), and past it the best responses, the
lower value and the Monte Carlo stop, the Result ``time_limit`` naming what was cut short."""

from __future__ import annotations

import copy
import time

from gamespec_levelset.game import linearized_game

from gamespec.flowfield.budget import Budget
from gamespec.flowfield.problem import evaluate_game
from gamespec.flowfield.simulation import simulate
from gamespec.flowfield.stages import covariance_game_spec, reachability_spec
from gamespec.loader import spec_from_dict
from gamespec.result import Status
from gamespec.solving import solve
from gamespec.terminal import Tracker
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
    assert "Monte Carlo, open_loop not finished" in result.message
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


def test_the_monte_carlo_counts_its_control_steps_and_stops_at_the_limit() -> None:
    """:func:`~gamespec.flowfield.simulation.simulate` advances the progress once per control step
    and, with no time left, stops after the first (None)."""
    spec, reach = _stages(100.0)
    game_spec = covariance_game_spec(spec, reach)
    data = evaluate_game(game_spec, game_spec.problem.parameters)
    stage = linearized_game(data)
    V, K = stage.game.controls(stage.game.nominal())
    x0 = data.origins.reshape(-1)
    tracker = Tracker("Monte Carlo", None)
    ensemble = simulate(data.field, stage.model, x0, V, K, 50, 0, 2, Budget(None, tracker))
    assert ensemble is not None and ensemble.positions.shape[0] == 50
    assert tracker.completed == stage.model.N > 1
    stopped = Tracker("Monte Carlo", None)
    assert simulate(data.field, stage.model, x0, V, K, 50, 0, 2, Budget(0.0, stopped)) is None
    assert stopped.completed == 1
