"""The CasADi build at N = 1000 Radau intervals (issue 16): the flat SX graph against the MX graph
around the mapped per-point function, build and first solve timed apart, on the cart-pole swing-up
(Kelly 2017) and both Zermelo files; the same optimum either way.

Run: ``python -m pytest benchmarks/test_bench_casadi_build.py --benchmark-enable -m slow``; compare
``build`` with ``solve`` within a graph, and the graphs with each other.
"""

from __future__ import annotations

import time

import pytest

import gamespec
from gamespec.solving import get_backend
from tests.conftest import PROBLEMS

FILES = {
    "cart_pole": PROBLEMS / "ocp" / "cart_pole_swing_up.yaml",
    "zermelo_min_time": PROBLEMS / "ch6" / "zermelo_min_time.yaml",
    "zermelo_max_range": PROBLEMS / "ch6" / "zermelo_max_range.yaml",
}
_OPTIMA: dict[str, float] = {}


@pytest.mark.slow
@pytest.mark.parametrize("graph", ["sx", "mx"])
@pytest.mark.parametrize("case", sorted(FILES))
def test_build_then_solve_at_n_1000(benchmark, case: str, graph: str) -> None:
    benchmark.group = f"{case}, N = 1000"
    spec = gamespec.load(FILES[case], ["method.intervals=1000", f"solver.options.casadi.graph={graph}"])
    times = {}

    def build_and_solve():
        tic = time.perf_counter()
        model = get_backend("casadi").compile(spec)
        times["build"] = time.perf_counter() - tic
        result = model.solve()
        times["solve"] = result.solve_time_s
        return result

    result = benchmark.pedantic(build_and_solve, rounds=1)
    benchmark.extra_info.update(times)
    assert result.ok
    expected = _OPTIMA.setdefault(case, result.objective)
    assert result.objective == pytest.approx(expected, rel=1e-8)
