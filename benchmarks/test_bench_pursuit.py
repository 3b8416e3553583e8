"""Pursuit-evasion speed: one OCP solve (build + solve) per problem file, the closed forms beside
them, and the Table 2.1 study's total time, serial.

Run: ``python -m pytest benchmarks/test_bench_pursuit.py --benchmark-enable`` (the study is marked
slow: add ``-m slow`` to time it; it starts from an empty store so nothing is resumed).
"""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.pursuit.simulation import simulate_to_capture
from gamespec.result import Status
from gamespec.suboptimal_study import points as study
from gamespec.suboptimal_study import study as suboptimal_study
from tests.conftest import PROBLEMS

CASES = {
    "constant_bearing_two_on_one": PROBLEMS / "ch2" / "constant_bearing_two_on_one.yaml",
    "constant_bearing_degenerate": PROBLEMS / "ch2" / "constant_bearing_degenerate.yaml",
    "pure_pursuit_two_on_one": PROBLEMS / "ch2" / "pure_pursuit_two_on_one.yaml",
    "relay_pure_pursuit": PROBLEMS / "ch2" / "relay_pure_pursuit.yaml",
    "relay_constant_bearing": PROBLEMS / "ch2" / "relay_constant_bearing.yaml",
    "mpse_optimal_evasion_cb": PROBLEMS / "ch3" / "mpse_optimal_evasion_cb.yaml",
}
ANALYTIC = [
    "constant_bearing_two_on_one",
    "constant_bearing_degenerate",
    "pure_pursuit_two_on_one",
    "mpse_optimal_evasion_cb",
]


def _solve(path, backend: str | None) -> float:
    result = gamespec.solve(gamespec.load(path), backend)
    assert result.ok
    return result.t_final


@pytest.mark.parametrize("case", sorted(CASES))
def test_ocp_solve(benchmark, case: str) -> None:
    """Load, generate the reduced OCP and its guess, build the NLP, solve, re-simulate."""
    benchmark.group = case
    benchmark.pedantic(_solve, args=(CASES[case], "casadi"), rounds=3, warmup_rounds=1)


@pytest.mark.parametrize("case", ANALYTIC)
def test_analytic(benchmark, case: str) -> None:
    """The closed form (CB) or eq. 2.27 suboptimal heading (PP), simulated with the true dynamics."""
    benchmark.group = case
    benchmark.pedantic(_solve, args=(CASES[case], "analytic"), rounds=3, warmup_rounds=1)


@pytest.mark.slow
def test_table_2_1_study_serial(benchmark, tmp_path) -> None:
    """All 720 points of the shipped study file, one process, from an empty store."""
    spec = gamespec.load(PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml", [f"store={tmp_path}"])
    result = benchmark.pedantic(gamespec.solve, args=(spec,), rounds=1)
    assert result.status == Status.OPTIMAL, result.message


def _every_twelfth_point():
    spec = gamespec.load(PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml")
    return list(study.study_points(spec).values())[::12]


@pytest.mark.parametrize("suboptimal", ["pursuit curve", "integrated"])
def test_table_2_1_points(benchmark, monkeypatch, suboptimal: str) -> None:
    """Issue 16: 60 of the 720 points, the suboptimal capture from the closed-form pursuit curve
    against the integrated true dynamics (the path before) as the baseline; the same variations."""
    benchmark.group = "Table 2.1, 60 points"
    points = _every_twelfth_point()
    expected = [suboptimal_study.evaluate(p).get("variation_percent") for p in points]
    if suboptimal == "integrated":
        monkeypatch.setattr(suboptimal_study, "constant_heading_pursuit", simulate_to_capture)
    rows = benchmark.pedantic(lambda: [suboptimal_study.evaluate(p) for p in points], rounds=1)
    got = [r.get("variation_percent") for r in rows]
    assert [g is None for g in got] == [e is None for e in expected]
    np.testing.assert_allclose(
        [g for g in got if g is not None], [e for e in expected if e is not None], atol=1e-6
    )
