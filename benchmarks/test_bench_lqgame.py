"""Chapter 4 timings: the §4.5.1 constrained game (load, build, Jacobi, Monte Carlo) on Clarabel
and SCS (goal: under 0.5 s on Clarabel), and the mean steering QP of §4.5.1 (the file without Σ_N,
which the ``qp`` backend takes) on each installed qpsolvers solver beside the closed form of
Prop. 10.

The covariance game's horizon (issue 16, item 6), CPU time (``time.process_time``) measured in the
same run: at N = 20, the file's game (Anderson-accelerated Jacobi, eq. 4.61 as one small cone per
column of ``W``) against the baseline kept here, :class:`ThesisFormPlayers` (eq. 4.62 as Lemma 13
writes it, one (n + p)-square cone, plain Jacobi as in Algorithm 2): the ratio, and the gains and
payoff of both; and the growth of the file's whole solve over N ∈ {10, 15, 20, 25}: each time over
the N = 10 one and the exponent (least-squares slope of log time on log N).

Run: ``python -m pytest benchmarks/test_bench_lqgame.py --benchmark-enable -s``.
"""

from __future__ import annotations

import time
from typing import Any

import cvxpy as cp
import numpy as np
import pytest
import qpsolvers
from gamespec_cvxpy.backend import CovariancePlayers, CvxpyOptions

import gamespec
from gamespec.lqgame.lifting import lift
from gamespec.lqgame.mean_steering import MeanGame
from gamespec.lqgame.solution import GameModel
from gamespec.specs.lq_game import LQGameSpec
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


HORIZONS = (10, 15, 20, 25)


class ThesisFormPlayers(CovariancePlayers):
    """The baseline: eq. 4.62 as Lemma 13 writes it, ``σ_max(W) ≤ √bound``, one (n + p)-square cone
    (Clarabel decomposes it afresh at every step, so every step is a new setup)."""

    @staticmethod
    def terminal_cone(W: Any, bound: Any) -> list[Any]:
        return [cp.sigma_max(W) <= cp.sqrt(bound)]


def _horizon(N: int, *settings: str) -> LQGameSpec:
    return gamespec.load(EXAMPLE, [f"problem.horizon={N}", "method.monte_carlo.samples=0", *settings])


def _covariance_game(players: type[CovariancePlayers], N: int, *settings: str) -> tuple[float, Any]:
    """CPU seconds of building the players and running Algorithm 2 with the file's method."""
    spec = _horizon(N, *settings)
    model = GameModel.build(spec.game())
    start = time.process_time()
    outcome = players(model, CvxpyOptions()).solve(spec.method.settings())
    return time.process_time() - start, (model, outcome)


def test_covariance_game_n20_against_the_thesis_form(benchmark) -> None:
    """Goal: N = 20 in ≤ 1.5 s with the same saddle point (the baseline took 3.8–6 s here)."""
    benchmark.group = "ch4 §4.5.1 covariance game, N = 20"
    baseline_s, (model, baseline) = _covariance_game(ThesisFormPlayers, 20, "method.acceleration=none")
    new_s, (_, outcome) = benchmark.pedantic(_covariance_game, args=(CovariancePlayers, 20), rounds=1)
    assert baseline.status.ok and outcome.status.ok
    mean = model.mean.payoff(*model.mean.upper_game())
    J = [model.covariance.payoff(o.kappa, o.ell) for o in (baseline, outcome)]
    assert mean + J[1] == pytest.approx(mean + J[0], rel=1e-8)
    gap = float(max(np.abs(outcome.kappa - baseline.kappa).max(), np.abs(outcome.ell - baseline.ell).max()))
    benchmark.extra_info.update(
        baseline_s=baseline_s,
        new_s=new_s,
        ratio=new_s / baseline_s,
        iterations={"baseline": baseline.iterations, "new": outcome.iterations},
        max_gain_gap=gap,
        covariance_payoffs=J,
    )
    print(
        f"\nN = 20: thesis form + Jacobi {baseline_s:.2f} s ({baseline.iterations} sweeps), column cones + "
        f"Anderson {new_s:.2f} s ({outcome.iterations} sweeps): ratio {new_s / baseline_s:.3f}; "
        f"gains within {gap:.1e}, J_Σ {J[0]:.10g} / {J[1]:.10g}, J {mean + J[0]:.12g} / {mean + J[1]:.12g}"
    )
    assert new_s < baseline_s / 2


def _solve_horizons() -> dict[int, tuple[float, gamespec.Result]]:
    runs = {}
    for N in HORIZONS:
        spec = _horizon(N)
        start = time.process_time()
        result = gamespec.solve(spec)
        runs[N] = (time.process_time() - start, result)
    return runs


def test_covariance_game_horizon_growth(benchmark) -> None:
    """The file's whole solve (``gamespec.solve``, Monte Carlo off) at each horizon, over N = 10."""
    benchmark.group = "ch4 §4.5.1 horizon growth"
    gamespec.solve(_horizon(HORIZONS[0]))
    runs = benchmark.pedantic(_solve_horizons, rounds=1)
    assert all(result.status.ok for _, result in runs.values())
    seconds = np.array([runs[N][0] for N in HORIZONS])
    exponent = float(np.polyfit(np.log(HORIZONS), np.log(seconds), 1)[0])
    benchmark.extra_info.update(
        seconds={N: runs[N][0] for N in HORIZONS},
        over_n10={N: runs[N][0] / runs[HORIZONS[0]][0] for N in HORIZONS},
        iterations={N: runs[N][1].iterations for N in HORIZONS},
        exponent=exponent,
    )
    rows = ", ".join(f"N = {N}: {runs[N][0]:.2f} s ({runs[N][1].iterations} sweeps)" for N in HORIZONS)
    print(f"\n{rows}; time ~ N^{exponent:.2f}")
