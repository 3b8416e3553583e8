"""Re-solves of the desensitized boat (``problems/ch6/zermelo_trajectory_desensitized.yaml``) for
new ``alpha`` (issue 24, item 1's goal for this file): with the analyses off, a re-solve should
spend at least :data:`GOAL` of its time inside ``CompiledModel.solve``.

One compile, then a re-solve per ``alpha`` in :data:`ALPHAS`, twice: with the analyses off, and,
as the baseline in the same run, with all of them (the 2000-sample Monte Carlo and the LQR
tracking of the file). Each solve of the compiled model is timed by wrapping it, and so are the
transform's ``apply`` (re-applied per point until the chain maps parameters instead) and
``invert``; the shares of the per-point time are written to the benchmark's ``extra_info`` and to
the terminal. Times are this process's CPU time (the solvers run in it), so a machine shared with
other work measures the same shares. The answers of the two passes must agree (the analyses change
no solution).

Run: ``python -m pytest benchmarks/test_bench_resolve_desensitized.py --benchmark-enable -s``.
"""

from __future__ import annotations

import time
from collections import defaultdict
from collections.abc import Callable
from typing import Any

import pytest

import gamespec
from gamespec.analyses import CACHE
from tests.conftest import PROBLEMS

FILE = PROBLEMS / "ch6" / "zermelo_trajectory_desensitized.yaml"
ALPHAS = [0.0, 25.0, 50.0, 75.0, 100.0, 200.0, 350.0, 500.0, 1000.0, 5000.0]
GOAL = 0.8
"""The share of a re-solve (analyses off) that should be inside ``CompiledModel.solve``."""


def _timed(spent: dict[str, float], key: str, call: Callable[..., Any]) -> Callable[..., Any]:
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        start = time.process_time()
        try:
            return call(*args, **kwargs)
        finally:
            spent[key] += time.process_time() - start

    return wrapper


def resolve_sweep(analyses: str) -> tuple[list[float], dict[str, float]]:
    """Objectives of the re-solves for :data:`ALPHAS` and the seconds spent: ``total`` (every
    ``Solver.solve``), ``solve`` (inside ``CompiledModel.solve``), ``apply`` and ``invert`` (the
    transforms')."""
    solver = gamespec.compile_spec(gamespec.load(FILE), analyses=analyses)
    spent: dict[str, float] = defaultdict(float)
    solver.compiled.solve = _timed(spent, "solve", solver.compiled.solve)
    for step in solver.steps:
        step.transform.apply = _timed(spent, "apply", step.transform.apply)
        step.transform.invert = _timed(spent, "invert", step.transform.invert)
    objectives = []
    for alpha in ALPHAS:
        start = time.process_time()
        objectives.append(solver.solve(parameters={"alpha": alpha}).objective)
        spent["total"] += time.process_time() - start
    return objectives, dict(spent)


def test_resolve_alpha_with_analyses_off(benchmark) -> None:
    benchmark.group = f"desensitized boat: {len(ALPHAS)} re-solves of alpha"
    CACHE.clear()
    start = time.process_time()
    baseline, on = resolve_sweep("all")
    with_analyses = time.process_time() - start
    objectives, off = benchmark.pedantic(resolve_sweep, args=("none",), rounds=1, iterations=1)
    assert objectives == pytest.approx(baseline, rel=1e-6)
    assert len(set(objectives)) == len(ALPHAS)
    share = off["solve"] / off["total"]
    per_point = {k: v / len(ALPHAS) for k, v in off.items()}
    benchmark.extra_info |= {
        "solve_share": share,
        "apply_share": off.get("apply", 0.0) / off["total"],
        "invert_share": off.get("invert", 0.0) / off["total"],
        "per_point_s": per_point,
        "per_point_with_analyses_s": on["total"] / len(ALPHAS),
        "analyses_on_over_off": on["total"] / off["total"],
        "goal": GOAL,
    }
    print(
        f"\nanalyses off: {per_point['total']:.3f} s per point, {share:.0%} inside CompiledModel.solve "
        f"(goal {GOAL:.0%}), {off.get('apply', 0.0) / off['total']:.0%} re-applying the transform, "
        f"{off.get('invert', 0.0) / off['total']:.0%} in invert; with the analyses: "
        f"{on['total'] / len(ALPHAS):.3f} s per point ({on['total'] / off['total']:.1f}x, "
        f"{with_analyses:.1f} s with the compile)"
    )
