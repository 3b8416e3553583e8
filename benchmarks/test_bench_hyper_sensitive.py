"""The hyper-sensitive problem (t_f = 1e4) with mesh refinement from 10 intervals (issue 25, item 5):
hp on both backends (degrees raised where the ph rule predicts it suffices, intervals split
otherwise and where the RK4 re-integration overflows) against h (every failing interval halved),
both to the file's relative defect of 1e-7, build + solve from the file's guess. ``extra_info``
holds the meshes, the final interval count, the NLP size and J's relative error against the boundary
layers' closed form.

Run: ``python -m pytest benchmarks/test_bench_hyper_sensitive.py --benchmark-enable``; compare the
means of the group (goal: hp faster and smaller than h); the hp runs also assert J within 1e-6 of
the closed form.
"""

from __future__ import annotations

import pytest

import gamespec
from tests.conftest import PROBLEMS
from tests.core.test_ocp_checks import _layers_value

HYPER_SENSITIVE = PROBLEMS / "ocp" / "hyper_sensitive.yaml"


def _refined(strategy: str, backend: str = "casadi") -> gamespec.Result:
    overrides = [f"method.refine.strategy={strategy}", "method.refine.max_iterations=30"]
    return gamespec.solve(gamespec.load(HYPER_SENSITIVE, overrides), backend)


def _record(benchmark, result: gamespec.Result) -> None:
    last = result.metrics["refinement"][-1]
    benchmark.extra_info["meshes"] = len(result.metrics["refinement"])
    benchmark.extra_info["intervals"] = last["intervals"]
    benchmark.extra_info["variables"] = last["variables"]
    benchmark.extra_info["relative_error"] = abs(result.objective / _layers_value(1.0, 1.5) - 1)


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_hp_refinement(benchmark, backend: str) -> None:
    benchmark.group = "hyper-sensitive from 10 intervals to a relative defect of 1e-7"
    result = benchmark.pedantic(_refined, args=("hp", backend), rounds=3, warmup_rounds=1)
    _record(benchmark, result)
    assert result.metrics["refinement_converged"]
    assert abs(result.objective / _layers_value(1.0, 1.5) - 1) < 1e-6


def test_h_refinement(benchmark) -> None:
    benchmark.group = "hyper-sensitive from 10 intervals to a relative defect of 1e-7"
    result = benchmark.pedantic(_refined, args=("h",), rounds=3, warmup_rounds=1)
    _record(benchmark, result)
    assert result.metrics["refinement_converged"]
