"""Chapter 7's receding horizon (§7.3.2, ``problems/ch7/asymmetric_obstacle.yaml``): one step (both
games ``G^u`` and ``G^v`` to convergence) on the compiled models, against the baseline of the same
step with every player's model compiled afresh; and a whole run (slow). Times, the ratio and the
iterations per step go to ``extra_info`` and the terminal. And ``game.scheme: joint`` against best
responses on the chapter-7 LQ and nonlinear files (compile and solve, CPU seconds, in the same run).

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


JOINT_CASES = {
    "lq_pursuit_evasion": [],
    "scalar_lq_three_sevenths": ["game.damping=0.3", "game.max_iterations=300"],
    "scalar_lq_saddle": ["game.damping=0.2", "game.max_iterations=300"],
    "homicidal_chauffeur": [],
    "unicycle_pursuit_evasion": ["game.max_iterations=100"],
}
"""``problems/ch7`` files and the best-response settings of the baseline (Gauss–Seidel; the damping
that makes it converge where one does: the scalar saddle game stalls at 7e-7 even damped by 0.2,
the unicycle game cycles)."""


def _solved(name: str, sets: list[str]):
    started = time.process_time()
    result = compile_spec(load(PROBLEMS / "ch7" / f"{name}.yaml", sets)).solve()
    return result, time.process_time() - started


@pytest.mark.parametrize("name", list(JOINT_CASES))
def test_joint_scheme_against_best_responses(benchmark, name: str) -> None:
    """Compile and solve with ``game.scheme: joint`` against best responses on the same file, CPU
    seconds of each, their ratio and the iterations (Newton iterations of the joint solve, sweeps
    of best responses); where best responses converge, the two payoffs agree."""
    responses, baseline = _solved(name, ["game.scheme=gauss_seidel", *JOINT_CASES[name]])
    joint = benchmark.pedantic(lambda: _solved(name, ["game.scheme=joint"]), rounds=3, iterations=1)[0]
    seconds = _solved(name, ["game.scheme=joint"])[1]
    assert joint.ok and joint.metrics["checks_passed"]["saddle_gap"], joint.message
    converged = all(run["converged"] for run in responses.metrics["best_response"].values())
    if converged:
        assert abs(joint.objective - responses.objective) <= 1e-5 * max(1.0, abs(responses.objective))
    info = {
        "joint_cpu_s": seconds,
        "best_response_cpu_s": baseline,
        "speedup": baseline / seconds,
        "joint_iterations": joint.iterations,
        "best_response_iterations": responses.iterations,
        "best_response_status": responses.status.value,
        "joint_objective": joint.objective,
        "best_response_objective": responses.objective,
    }
    benchmark.extra_info |= info
    print(
        f"\n{name}: joint {seconds:.2f} s CPU, {joint.iterations} Newton iterations, {joint.status.value} "
        f"J = {joint.objective:.10g}; best responses {baseline:.2f} s, {responses.iterations} sweeps, "
        f"{responses.status.value} J = {responses.objective:.10g}; ratio {baseline / seconds:.2f}"
    )
