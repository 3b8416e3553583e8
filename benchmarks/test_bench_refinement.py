"""Adaptive mesh refinement against a uniform mesh of the same final accuracy (issue 17, item 5):
the hang glider refined from 10 intervals to a relative defect of 1e-6, by splitting intervals (h) and
by raising their degree where the defect predicts it suffices (hp), against the coarsest uniform mesh
(doubling from the h-refined interval count) whose relative defect is at least as small as h's. All
build + solve from the file's guess; the NLP size is in ``extra_info``.

Run: ``python -m pytest benchmarks/test_bench_refinement.py --benchmark-enable``; compare the means
of the group (goal: refinement faster and smaller than the uniform mesh).
"""

from __future__ import annotations

from functools import cache

import gamespec
from tests.conftest import PROBLEMS

HANG_GLIDER = PROBLEMS / "ocp" / "hang_glider.yaml"
TOLERANCE = 1e-6


def _solve(overrides: list[str]) -> gamespec.Result:
    return gamespec.solve(gamespec.load(HANG_GLIDER, overrides))


def _refined(strategy: str = "h") -> gamespec.Result:
    refine = [f"method.refine.tolerance={TOLERANCE}", f"method.refine.strategy={strategy}"]
    return _solve(["method.intervals=10", *refine])


@cache
def _uniform_intervals() -> int:
    reached = _refined().checks["max_defect_relative"]
    n = _refined().metrics["refinement"][-1]["intervals"]
    while _solve([f"method.intervals={n}"]).checks["max_defect_relative"] > reached:
        n *= 2
    return n


def test_refined_mesh(benchmark) -> None:
    benchmark.group = "hang glider to a relative defect of 1e-6"
    result = benchmark.pedantic(_refined, rounds=3, warmup_rounds=1)
    benchmark.extra_info["intervals"] = result.metrics["refinement"][-1]["intervals"]
    benchmark.extra_info["variables"] = result.metrics["refinement"][-1]["variables"]
    assert result.metrics["refinement_converged"]


def test_hp_refined_mesh(benchmark) -> None:
    benchmark.group = "hang glider to a relative defect of 1e-6"
    result = benchmark.pedantic(_refined, args=("hp",), rounds=3, warmup_rounds=1)
    benchmark.extra_info["intervals"] = result.metrics["refinement"][-1]["intervals"]
    benchmark.extra_info["variables"] = result.metrics["refinement"][-1]["variables"]
    assert result.metrics["refinement_converged"]


def test_uniform_mesh(benchmark) -> None:
    benchmark.group = "hang glider to a relative defect of 1e-6"
    n = _uniform_intervals()
    result = benchmark.pedantic(_solve, args=([f"method.intervals={n}"],), rounds=3, warmup_rounds=1)
    benchmark.extra_info["intervals"] = n
    benchmark.extra_info["variables"] = (3 * n + 1) * 4 + 3 * n
    assert result.checks["max_defect_relative"] <= _refined().checks["max_defect_relative"]
