"""The hyper-sensitive problem (t_f = 1e4) with mesh refinement from 10 intervals (issue 25, item 5):
hp (degrees raised where the ph rule predicts it suffices, intervals split otherwise and where the
RK4 re-integration overflows) against h (every failing interval halved), both to the file's relative
defect of 1e-7, build + solve from the file's guess. ``extra_info`` holds the meshes, the final
interval count, the NLP size and J's relative error against the boundary layers' closed form.

Run: ``python -m pytest benchmarks/test_bench_hyper_sensitive.py --benchmark-enable``; compare the
means of the group (goal: hp faster and smaller than h).
"""

from __future__ import annotations

import gamespec
from tests.conftest import PROBLEMS
from tests.core.test_ocp_checks import _layers_value

HYPER_SENSITIVE = PROBLEMS / "ocp" / "hyper_sensitive.yaml"


def _refined(strategy: str) -> gamespec.Result:
    overrides = [f"method.refine.strategy={strategy}", "method.refine.max_iterations=30"]
    return gamespec.solve(gamespec.load(HYPER_SENSITIVE, overrides))


def _record(benchmark, result: gamespec.Result) -> None:
    last = result.metrics["refinement"][-1]
    benchmark.extra_info["meshes"] = len(result.metrics["refinement"])
    benchmark.extra_info["intervals"] = last["intervals"]
    benchmark.extra_info["variables"] = last["variables"]
    benchmark.extra_info["relative_error"] = abs(result.objective / _layers_value(1.0, 1.5) - 1)


def test_hp_refinement(benchmark) -> None:
    benchmark.group = "hyper-sensitive from 10 intervals to a relative defect of 1e-7"
    result = benchmark.pedantic(_refined, args=("hp",), rounds=3, warmup_rounds=1)
    _record(benchmark, result)
    assert result.metrics["refinement_converged"]


def test_h_refinement(benchmark) -> None:
    benchmark.group = "hyper-sensitive from 10 intervals to a relative defect of 1e-7"
    result = benchmark.pedantic(_refined, args=("h",), rounds=3, warmup_rounds=1)
    _record(benchmark, result)
    assert result.metrics["refinement_converged"]
