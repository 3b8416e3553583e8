"""Chapter 7's receding horizon (§7.3.2, ``problems/ch7/asymmetric_obstacle.yaml``): one step (both
games ``G^u`` and ``G^v`` to convergence) on the compiled models, against the baseline of the same
step with every player's model compiled afresh; and a whole run (slow). Times, the ratio and the
iterations per step go to ``extra_info`` and the terminal.

Run: ``python -m pytest benchmarks/test_bench_games.py --benchmark-enable -s`` (``-m slow`` adds
the whole run).
"""

from __future__ import annotations

import time

import pytest

from gamespec.games.equilibrium import GameModel
from gamespec.games.problems import initial_state
from gamespec.loader import load
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS

FILE = PROBLEMS / "ch7" / "asymmetric_obstacle.yaml"


def one_step(model: GameModel) -> dict[str, int]:
    """Both games from the initial state; the iterations of each."""
    game = model.game
    x0, t0 = initial_state(game), game.problem.time.initial
    return {view: model.solve(view, x0, t0).run.iterations for view in model.views}


def test_one_receding_horizon_step(benchmark) -> None:
    game = load(FILE)
    tic = time.perf_counter()
    fresh = one_step(GameModel(game))
    baseline = time.perf_counter() - tic
    model = GameModel(game)
    iterations = benchmark.pedantic(one_step, args=(model,), rounds=5, iterations=1)
    step = benchmark.stats.stats.mean if benchmark.stats else baseline
    assert iterations == fresh
    benchmark.extra_info |= {"fresh_build_s": baseline, "iterations": iterations, "speedup": baseline / step}
    print(f"\none step: {step:.3f} s compiled, {baseline:.3f} s with fresh builds; iterations {iterations}")


@pytest.mark.slow
def test_whole_run(benchmark) -> None:
    solver = compile_spec(load(FILE))
    result = benchmark.pedantic(solver.solve, rounds=1, iterations=1)
    m = result.metrics
    per_step = [max(g["iterations"] for g in s["games"].values()) for s in m["per_step"]]
    benchmark.extra_info |= {"steps": m["steps"], "iterations_per_step": per_step, "stop": m["stop"]}
    print(f"\nwhole run: {m['steps']} steps, stop {m['stop']}, iterations per step {per_step}")
