"""Mean steering (section 4.3): Prop. 9's saddle point, Prop. 10's upper game in closed form against
the same game as a QP (qpsolvers, several solvers), and Lemma 11's reachability test."""

from __future__ import annotations

import numpy as np
import pytest
import qpsolvers
from scipy.sparse import csc_matrix

from gamespec.lqgame.checks import reachability
from gamespec.lqgame.mean_steering import MeanGame
from gamespec.lqgame.solution import GameModel
from tests.lqgame.conftest import random_game

TIGHT = {"proxqp": {"eps_abs": 1e-10}, "osqp": {"eps_abs": 1e-9, "eps_rel": 1e-9}, "clarabel": {}}


def _qp(mean: MeanGame, solver: str) -> np.ndarray:
    data = mean.upper_game_qp()
    P, A = data.P, data.A
    if solver not in qpsolvers.dense_solvers:
        P, A = csc_matrix(P), None if A is None else csc_matrix(A)
    x = qpsolvers.solve_qp(P, data.q, A=A, b=data.b, solver=solver, **TIGHT[solver])
    assert x is not None
    return x


def test_saddle_point_is_stationary_and_a_saddle(model: GameModel):
    """eq. 4.30: both gradients vanish; J_μ is convex in Ū and concave in V̄ (eq. 4.33)."""
    mean = model.mean
    U, V = mean.saddle_point()
    np.testing.assert_allclose(mean.H_uu @ U + mean.H_uv @ V + mean.free_u, 0, atol=1e-9)
    np.testing.assert_allclose(mean.H_uv.T @ U + mean.H_vv @ V + mean.free_v, 0, atol=1e-9)
    rng = np.random.default_rng(0)
    value = mean.payoff(U, V)
    for _ in range(20):
        assert mean.payoff(U + rng.standard_normal(U.size), V) >= value
        assert mean.payoff(U, V + rng.standard_normal(V.size)) <= value


def test_unconstrained_upper_game_is_the_saddle_point(model: GameModel):
    """Without a target, the upper game (controller first, stopper best-responding) has the value
    and the minimizer of Prop. 9, since the saddle point exists and is unique."""
    game = model.game
    free = GameModel.build(type(game)(**{**game.__dict__, "muN": None}))
    U_qp = _qp(free.mean, "proxqp")
    U_star, V_star = free.mean.saddle_point()
    np.testing.assert_allclose(U_qp, U_star, atol=1e-6)
    np.testing.assert_allclose(free.mean.stopper_response(U_qp), V_star, atol=1e-6)


@pytest.mark.parametrize("solver", ["proxqp", "clarabel", "osqp"])
def test_upper_game_closed_form_agrees_with_qp(model: GameModel, solver: str):
    """Prop. 10 (eq. 4.45–4.46) and the QP of eq. 4.43 give the same Ū; the target is met."""
    U_closed, V_closed = model.mean.upper_game()
    U_qp = _qp(model.mean, solver)
    scale = max(1.0, np.abs(U_closed).max())
    np.testing.assert_allclose(U_qp, U_closed, atol=1e-6 * scale)
    np.testing.assert_allclose(model.mean.trajectory(U_closed, V_closed)[-1], model.game.muN, atol=1e-8)


def test_upper_game_stopper_plays_its_best_response(model: GameModel):
    """At Prop. 10's solution the stopper cannot gain by deviating (eq. 4.39b)."""
    U, V = model.mean.upper_game()
    rng = np.random.default_rng(1)
    value = model.mean.payoff(U, V)
    for _ in range(20):
        assert model.mean.payoff(U, V + 0.1 * rng.standard_normal(V.size)) <= value


def test_rank_test_names_the_unreachable_component():
    """A state no input reaches (a decoupled, stable component) makes Lemma 11 fail there only."""
    game = random_game(5)
    A, B, C = game.A.copy(), game.B.copy(), game.C.copy()
    A[:, 2, :] = 0
    A[:, :, 2] = 0
    A[:, 2, 2] = 0.5
    B[:, 2] = 0
    C[:, 2] = 0
    stuck = GameModel.build(type(game)(**{**game.__dict__, "A": A, "B": B, "C": C, "muN": np.ones(game.n)}))
    reach = stuck.assumptions.reachability
    assert reach.rank == game.n - 1
    assert not reach.reachable
    assert reach.unreachable_components == [2]
    assert "[2]" in stuck.unreachable_mean()
    free = GameModel.build(type(game)(**{**stuck.game.__dict__, "muN": np.array([1.0, 1.0, np.nan])}))
    assert reachability(free.mean).reachable
    U, V = free.mean.upper_game()
    np.testing.assert_allclose(free.mean.trajectory(U, V)[-1, :2], 1.0, atol=1e-8)
