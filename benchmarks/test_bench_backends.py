"""The two OCP backends side by side on every shipped ``optimal_control`` file: build (spec →
backend model) and a cold solve of the built model (from the file's guess, warm start off), each
in its own group so the CasADi/Pyomo ratio reads off directly. The Pyomo build writes the NL file
once; its solve rewrites the file's bounds and start segments and runs the solver process.

Run: ``python -m pytest benchmarks/test_bench_backends.py --benchmark-enable``.
"""

from __future__ import annotations

import pytest

import gamespec
from gamespec.solving import compile_spec
from tests.pyomo.cases import OCP_FILES

BACKENDS = ("casadi", "pyomo")
COLD = {"warm_start": False}


@pytest.fixture(scope="module")
def objectives() -> dict[str, float]:
    """CasADi's objective per file: every benchmarked solve must reach it."""
    return {path.stem: gamespec.solve(path, "casadi").objective for path in OCP_FILES}


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("path", OCP_FILES, ids=lambda p: p.stem)
def test_build(benchmark, path, backend: str) -> None:
    spec = gamespec.load(path)
    benchmark.group = f"{path.stem}: build"
    solver = benchmark.pedantic(compile_spec, args=(spec, backend, COLD), rounds=5, warmup_rounds=1)
    assert solver.build_time_s > 0


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("path", OCP_FILES, ids=lambda p: p.stem)
def test_solve(benchmark, objectives, path, backend: str) -> None:
    solver = compile_spec(gamespec.load(path), backend, COLD)
    benchmark.group = f"{path.stem}: solve"
    result = benchmark.pedantic(solver.solve, rounds=5, warmup_rounds=1)
    assert result.status.value == "optimal"
    assert result.objective == pytest.approx(objectives[path.stem], rel=1e-4)
