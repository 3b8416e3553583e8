"""Which solution an ``lq_stochastic_game`` Result holds (:mod:`gamespec.lqgame.equilibrium`): the
concept, both payoffs and each player's best-response improvement, checked against independent
solves.

- Without a target mean or covariance the game is Prop. 9's saddle (mean) with the UCSG gains
  (eq. 4.59): no player gains by a best response.
- With a target mean the mean part is the controller's upper value (Prop. 10): the stopper's input
  is its best response (no gain); the controller, were the stopper's inputs fixed, would reach the
  target at a lower cost — the value of that equality-constrained QP is computed here with CVXPY
  from the lifted matrices (eqs. 4.18, 4.21), independently of the code's KKT solve.
"""

from __future__ import annotations

import cvxpy as cp
import numpy as np
import pytest

import gamespec
from gamespec.lqgame.solution import GameModel
from tests.conftest import PROBLEMS

MEAN_STEERING = PROBLEMS / "ch4" / "test_example_mean_steering.yaml"
QUIET = ["method.monte_carlo.samples=0"]


def test_without_targets_the_game_is_a_saddle_with_no_gain():
    result = gamespec.solve(gamespec.load(MEAN_STEERING, ["problem.terminal={}", *QUIET]))
    m = result.metrics
    assert result.status is gamespec.Status.OPTIMAL
    assert m["solution_concept"] == "saddle" and m["solution_concepts"] == {
        "mean": "saddle",
        "covariance": "saddle",
    }
    assert m["payoffs"] == {"controller": result.objective, "stopper": result.objective}
    assert abs(result.checks["saddle_gap"]) <= 1e-10 * abs(result.objective)
    assert m["checks_passed"]["saddle_gap"]
    assert m["lower_value"] == m["upper_value"] == result.objective


def _controller_value(model: GameModel, V: np.ndarray) -> float:
    """``min_Ū J_μ(Ū, V̄)`` subject to the target mean against the fixed ``V̄``, by CVXPY."""
    L, game = model.lifted, model.game
    U = cp.Variable(L.B.shape[1])
    X = L.A @ game.mu0 + L.B @ U + L.C @ V
    rows = ~np.isnan(game.muN)
    E = L.terminal(np.eye(L.A.shape[0]))[rows]
    cost = cp.quad_form(X, cp.psd_wrap(L.Q)) + cp.quad_form(U, cp.psd_wrap(L.R)) - float(V @ L.S @ V)
    problem = cp.Problem(cp.Minimize(cost), [game.muN[rows] == E @ X])
    problem.solve(solver="CLARABEL")
    return float(problem.value)


def test_an_upper_value_names_itself_and_its_gains():
    spec = gamespec.load(MEAN_STEERING, QUIET)
    result = gamespec.solve(spec, "cvxpy")
    m = result.metrics
    assert m["solution_concept"] == "upper_value" and m["solution_concepts"]["mean"] == "upper_value"
    mean = m["improvements_by_part"]["mean"]
    assert abs(mean["stopper"]) <= 1e-9 * abs(m["mean_payoff"])
    assert m["checks_passed"]["follower_gap"] and "saddle_gap" not in result.checks
    model = GameModel.build(spec.game())
    V = np.column_stack([result.controls["v1"], result.controls["v2"]]).ravel()
    want = m["mean_payoff"] - _controller_value(model, V)
    assert want > 0
    assert mean["controller"] == pytest.approx(want, rel=1e-5)
    assert m["saddle_gap"] == pytest.approx(max(m["improvements"].values()))
