"""Chapter 4 timings: the §4.5.1 constrained game (load, build, Jacobi, Monte Carlo) on Clarabel
and SCS (goal: under 0.5 s on Clarabel), and the mean steering QP of §4.5.1 (the file without Σ_N,
which the ``qp`` backend takes) on each installed qpsolvers solver beside the closed form of
Prop. 10.

Run: ``python -m pytest benchmarks/test_bench_lqgame.py --benchmark-enable``.
"""

from __future__ import annotations

import numpy as np
import pytest
import qpsolvers

import gamespec
from gamespec.lqgame.lifting import lift
from gamespec.lqgame.mean_steering import MeanGame
from tests.conftest import PROBLEMS

EXAMPLE = PROBLEMS / "ch4" / "test_example.yaml"
MEAN_STEERING = PROBLEMS / "ch4" / "test_example_mean_steering.yaml"


def _solve_example(solver: str) -> gamespec.Result:
    return gamespec.solve(gamespec.load(EXAMPLE), options={"solver": solver})


@pytest.mark.parametrize("solver", ["CLARABEL", "SCS"])
def test_jacobi_test_example(benchmark, solver: str) -> None:
    benchmark.group = "ch4 §4.5.1 Jacobi, total"
    result = benchmark.pedantic(_solve_example, args=(solver,), rounds=5, warmup_rounds=1)
    assert result.ok and result.checks["terminal_covariance_violation"] < 1e-6


@pytest.mark.parametrize("solver", qpsolvers.available_solvers)
def test_mean_qp(benchmark, solver: str) -> None:
    benchmark.group = "ch4 §4.5.1 mean QP"
    model = gamespec.compile_spec(MEAN_STEERING, "qp", options={"solver": solver}).compiled
    outcome = benchmark.pedantic(model.solve_mean, rounds=20, warmup_rounds=1)
    closed, _ = model.model.mean.upper_game()
    assert outcome.status.ok
    assert np.abs(outcome.U - closed).max() < 1e-3 * np.abs(closed).max()


def test_mean_closed_form(benchmark) -> None:
    """Prop. 10 from the lifted matrices (including the products and solves the QP data needs)."""
    benchmark.group = "ch4 §4.5.1 mean QP"
    game = gamespec.load(MEAN_STEERING).game()
    lifted = lift(game)
    benchmark.pedantic(lambda: MeanGame(game, lifted).upper_game(), rounds=20, warmup_rounds=1)
