"""gamespec's CasADi backend against hand-written CasADi Opti collocations of the same
discretization: build + solve, per problem (goal: gamespec ≤ 1.2× the hand-written time).

Run: ``python -m pytest benchmarks/test_bench_casadi.py --benchmark-enable``; compare the means in
each group.
"""

from __future__ import annotations

import pytest

import gamespec
from benchmarks import opti_baselines
from tests.conftest import PROBLEMS

CASES = {
    "pure_pursuit_two_on_one": (
        PROBLEMS / "ch2" / "pure_pursuit_two_on_one.yaml",
        opti_baselines.two_on_one_pure_pursuit,
    ),
    "zermelo_max_range": (PROBLEMS / "ch6" / "zermelo_max_range.yaml", opti_baselines.zermelo_max_range),
}


def _gamespec_build_and_solve(path) -> float:
    return gamespec.solve(gamespec.load(path)).objective


@pytest.mark.parametrize("case", sorted(CASES))
def test_gamespec_casadi(benchmark, case) -> None:
    path, baseline = CASES[case]
    benchmark.group = case
    objective = benchmark.pedantic(_gamespec_build_and_solve, args=(path,), rounds=5, warmup_rounds=1)
    assert objective == pytest.approx(baseline(), rel=1e-6)


@pytest.mark.parametrize("case", sorted(CASES))
def test_hand_written_opti(benchmark, case) -> None:
    _, baseline = CASES[case]
    benchmark.group = case
    benchmark.pedantic(baseline, rounds=5, warmup_rounds=1)
