"""Chapter 6 timings: sensitivity functions (n + nℓ = 4 states) against Seywald's sensitivity matrix
((n+ℓ)² + n + ℓ = 12 states) on the minimum-time boat, build + solve, same α and mesh — once on the
identical problem J = t_f + α S1(t_f)² (eq. 6.30; both must find the same t_f) and once with
Seywald's own running cost (eq. 6.7); and the Monte Carlo of 10⁴ open-loop samples against one
nominal re-simulation in the same run.

Run: ``python -m pytest benchmarks/test_bench_desensitize.py --benchmark-enable``.
"""

from __future__ import annotations

import numpy as np
import pytest

from gamespec.desensitize.montecarlo import monte_carlo
from gamespec.desensitize.simulate import open_loop, rk4
from gamespec.desensitize.spec import MonteCarloOptions
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.symbolic.language import symbol
from tests.desensitize.helpers import SEYWALD, TRAJECTORY, file_solver

NO_MC = {"monte_carlo": {"samples": 0}}
FINAL_TERM = {"trajectory": None, "final": {"S_x1_rho": "alpha"}}


def _build_and_solve(edit: dict):
    return file_solver(SEYWALD, edit={**NO_MC, **edit}).solve()


@pytest.mark.parametrize("method", ["sensitivity", "seywald"])
def test_final_term_build_and_solve(benchmark, method: str) -> None:
    benchmark.group = "ch6 min-time boat, t_f + alpha S1(t_f)^2: build + solve"
    result = benchmark.pedantic(_build_and_solve, args=({"method": method, **FINAL_TERM},), rounds=5)
    reference = _build_and_solve({"method": "sensitivity", **FINAL_TERM})
    assert result.ok
    assert result.t_final == pytest.approx(reference.t_final, rel=1e-6)


@pytest.mark.parametrize("method", ["sensitivity", "seywald"])
def test_running_term_build_and_solve(benchmark, method: str) -> None:
    benchmark.group = "ch6 min-time boat, running sensitivity cost (eq. 6.16 / eq. 6.7): build + solve"
    result = benchmark.pedantic(_build_and_solve, args=({"method": method},), rounds=5)
    assert result.ok


@pytest.fixture(scope="module")
def boat():
    solver = file_solver(TRAJECTORY, edit=NO_MC)
    return solver.spec, solver.solve()


def test_monte_carlo_10k(benchmark, boat) -> None:
    benchmark.group = "ch6 Monte Carlo of the maximum-range boat"
    spec, result = boat
    options = MonteCarloOptions(samples=10_000, seed=0)
    metrics, _ = benchmark.pedantic(
        monte_carlo, args=(SymbolicOcp(spec), result, spec.problem.uncertain, options), rounds=5
    )
    assert metrics["samples"] == 10_000


def test_one_nominal_resimulation(benchmark, boat) -> None:
    """The baseline: the same RK4 grid for a single sample."""
    benchmark.group = "ch6 Monte Carlo of the maximum-range boat"
    spec, result = boat
    ocp = SymbolicOcp(spec)
    u = open_loop(result, ocp.controls)
    params = {symbol(k): v for k, v in result.parameters.items()}
    x0 = np.zeros((2, 1))
    steps = MonteCarloOptions().steps
    benchmark.pedantic(
        rk4,
        args=(ocp, x0, u, params, 0.0, float(result.t_final), steps),
        rounds=5,
    )
