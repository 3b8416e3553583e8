"""``solve_time_s`` is the time the caller waited for the solve, in every kind (issue 28 item 1)."""

from __future__ import annotations

import time

import pytest

import gamespec
from tests.conftest import PROBLEMS


@pytest.mark.parametrize(
    "path", ["ocp/bryson_denham.yaml", "ch7/lq_pursuit_evasion.yaml", "ch3/mpme_ten_on_five.yaml"]
)
def test_solve_time_is_the_wall_clock_of_the_solve(path) -> None:
    solver = gamespec.compile_spec(PROBLEMS / path)
    start = time.perf_counter()
    result = solver.solve()
    waited = time.perf_counter() - start
    assert result.ok, result.message
    assert 0.5 * waited < result.solve_time_s <= waited
