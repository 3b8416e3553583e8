"""Runtime parameters through the chain: a sweep of 20 evader speeds of the two-on-one
constant-bearing engagement, compiled once and re-solved 20 times (the engagement → OCP transform's
parameter map, the CasADi NLP reused) against 20 fresh solves (load, transform, build, solve).

Both start each NLP from the same guess, so the answers are the same; the speed-up (goal: ≥ 3×) is
the baseline's time over the compiled sweep's, measured in the same run and written to the
benchmark's ``extra_info`` and to the terminal. It is run at the file's grid (40 intervals), where
a build costs about as much as a re-solve's fixed work (generating the OCP and its guess from a
simulation, the re-simulation check), and at 120 intervals, where the build dominates.

Run: ``python -m pytest benchmarks/test_bench_chain.py --benchmark-enable -s``.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

import gamespec
from tests.conftest import PROBLEMS

FILE = PROBLEMS / "ch2" / "constant_bearing_two_on_one.yaml"
SPEEDS = [float(v) for v in np.linspace(0.3, 0.6, 20)]


def fresh_sweep(grid: list[str]) -> list[float]:
    """20 independent ``gamespec solve FILE --set evader.speed=v``."""
    return [gamespec.solve(gamespec.load(FILE, [*grid, f"evader.speed={v!r}"])).t_final for v in SPEEDS]


def compiled_sweep(grid: list[str]) -> list[float]:
    """One compile, then a re-solve per speed with the engagement's own parameter name."""
    solver = gamespec.compile_spec(gamespec.load(FILE, grid))
    return [solver.solve(parameters={"evader.speed": v}).t_final for v in SPEEDS]


@pytest.mark.parametrize("intervals", [40, 120])
def test_compile_once_against_fresh_solves(benchmark, intervals: int) -> None:
    benchmark.group = f"chain: 20 evader speeds, {intervals} intervals"
    grid = [f"method.intervals={intervals}"]
    compiled_sweep(grid)
    start = time.perf_counter()
    fresh = fresh_sweep(grid)
    baseline = time.perf_counter() - start
    start = time.perf_counter()
    resolved = benchmark.pedantic(compiled_sweep, args=(grid,), rounds=1, iterations=1)
    chained = time.perf_counter() - start
    assert resolved == pytest.approx(fresh, rel=1e-9)
    assert len(set(resolved)) == len(SPEEDS)
    benchmark.extra_info["fresh_s"] = baseline
    benchmark.extra_info["compiled_s"] = chained
    benchmark.extra_info["speedup"] = baseline / chained
    print(f"\n{intervals} intervals: 20 fresh solves {baseline:.3f} s, compile once + 20 re-solves ", end="")
    print(f"{chained:.3f} s: ", end="")
    print(f"{baseline / chained:.2f}x")
