"""Feedback Nash equilibria of LQ games by coupled Riccati equations (:mod:`gamespec.games.feedback`),
against closed forms, the independent best-response LQR, and the discrete-time recursion."""

from __future__ import annotations

import numpy as np
import pytest

from gamespec.games.feedback import (
    LQGame,
    LQPlayer,
    best_response_improvements,
    discrete_feedback_nash,
    feedback_nash,
    profile_values,
)


def _scalar_zero_sum(a: float, q: float, s: float, gamma2: float, T: float, x0: float = 1.0) -> LQGame:
    """``ẋ = a x + u + v``, ``J = ½ s x(T)² + ½ ∫ (q x² + u² − γ² v²) dt``: u minimizes, v maximizes."""
    A = np.array([[a, 0.0], [0.0, 0.0]])
    B = np.array([[1.0, 1.0], [0.0, 0.0]])
    Q, S, R = np.diag([q, 0.0]), np.diag([s, 0.0]), np.diag([1.0, -gamma2])
    N = np.zeros((2, 2))
    players = (
        LQPlayer("u", slice(0, 1), Q, N, R, S),
        LQPlayer("v", slice(1, 2), -Q, -N, -R, -S),
    )
    return LQGame(A, B, players, np.array([x0, 1.0]), 0.0, T)


def _scalar_value(a: float, q: float, s: float, gamma2: float, T: float) -> float:
    """½ P(0) from ``−Ṗ = 2aP + q − P²(1 − 1/γ²)``, ``P(T) = s``, by a fine RK4 (no SciPy)."""
    sigma = 1.0 - 1.0 / gamma2
    steps = 20_000
    h = T / steps
    P = s

    def f(P: float) -> float:
        return 2 * a * P + q - sigma * P * P

    for _ in range(steps):
        k1 = f(P)
        k2 = f(P + h / 2 * k1)
        k3 = f(P + h / 2 * k2)
        k4 = f(P + h * k3)
        P += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return 0.5 * P


@pytest.mark.parametrize(
    ("gamma2", "value"),
    [(1.2, 3 / 7), (0.8, 2 / 3)],
    ids=["open-loop saddle too", "feedback saddle only"],
)
def test_scalar_zero_sum_feedback_saddle_has_the_closed_form_value(gamma2, value) -> None:
    """a = q = 0, s = 1, T = 1: ``1/P(t) = 1 + (1 − 1/γ²)(1 − t)``, value ½ P(0) = 3/7 (γ² = 1.2)
    and 2/3 (γ² = 0.8, where the maximizer's open-loop Riccati equation escapes at t = 0.2)."""
    solution = feedback_nash(_scalar_zero_sum(0.0, 0.0, 1.0, gamma2, 1.0))
    assert solution.exists
    assert solution.values[0] == pytest.approx(value, rel=1e-9)
    assert solution.values[1] == pytest.approx(-value, rel=1e-9)


def test_scalar_zero_sum_with_drift_and_state_weight() -> None:
    game = _scalar_zero_sum(-0.5, 2.0, 2.0, 3.0, 2.0)
    solution = feedback_nash(game)
    assert solution.values[0] == pytest.approx(_scalar_value(-0.5, 2.0, 2.0, 3.0, 2.0), rel=1e-9)
    assert max(abs(g) for g in best_response_improvements(game, solution.gain)) < 1e-8


def test_a_conjugate_point_is_reported_with_its_time() -> None:
    """γ² = 0.5: ``1/P(t) = 1 − (T − t)`` from P(T) = 1 reaches 0 (P escapes) at t = T − 1."""
    solution = feedback_nash(_scalar_zero_sum(0.0, 0.0, 1.0, 0.5, 1.0 + 1e-3))
    assert not solution.exists
    assert solution.escape_time == pytest.approx(1e-3, abs=1e-5)
    assert "escapes" in solution.reason


def _nonzero_sum() -> LQGame:
    """Two players steering one planar point with their own targets (affine terms in the costs)."""
    k = 3
    A = np.array([[0.1, 1.0, 0.0], [-0.3, -0.2, 0.0], [0.0, 0.0, 0.0]])
    B = np.array([[0.0, 0.0], [1.0, 0.5], [0.0, 0.0]])

    def target(x: float, weight: float) -> np.ndarray:
        d = np.array([1.0, 0.0, -x])
        return weight * np.outer(d, d)

    N = np.zeros((k, 2))
    one = LQPlayer("one", slice(0, 1), target(1.0, 1.0), N, np.diag([1.0, 0.2]), target(1.0, 4.0))
    two = LQPlayer("two", slice(1, 2), target(-0.5, 0.5), N, np.diag([0.0, 2.0]), target(-0.5, 1.0))
    return LQGame(A, B, (one, two), np.array([0.2, 0.0, 1.0]), 0.0, 3.0)


def test_nonzero_sum_no_player_gains_by_its_own_lqr_reply() -> None:
    game = _nonzero_sum()
    solution = feedback_nash(game)
    assert solution.exists
    assert max(abs(g) for g in best_response_improvements(game, solution.gain)) < 1e-7


def test_a_law_that_is_not_an_equilibrium_is_improved_on() -> None:
    """The check can fail: with player two's gains halved, player two's own LQR reply improves."""
    game = _nonzero_sum()
    solution = feedback_nash(game)
    scale = np.array([[1.0], [0.5]])
    improvements = best_response_improvements(game, lambda t: scale * solution.gain(t))
    assert improvements[1] > 1e-3
    assert min(improvements) > -1e-9, "a best reply never does worse than the law it replaces"


def test_profile_values_of_the_equilibrium_are_its_values() -> None:
    game = _nonzero_sum()
    solution = feedback_nash(game)
    np.testing.assert_allclose(profile_values(game, solution.gain), solution.values, rtol=1e-8)


def test_discrete_recursion_converges_to_the_continuous_equilibrium() -> None:
    """Two implementations agree: Euler steps of the game (A_k = I + hA, B_k = hB, weights × h) give
    the continuous values to O(h)."""
    game = _nonzero_sum()
    continuous = feedback_nash(game).values
    errors = []
    for stages in (200, 400):
        h = (game.T - game.t0) / stages
        A = [np.eye(game.k) + h * game.A] * stages
        B = [h * game.B] * stages
        players = [LQPlayer(p.name, p.controls, h * p.Q, h * p.N, h * p.R, p.S) for p in game.players]
        discrete = discrete_feedback_nash(A, B, players, game.x0).values
        errors.append(max(abs(d - c) for d, c in zip(discrete, continuous, strict=True)))
    assert errors[1] < 0.6 * errors[0] and errors[1] < 5e-3


def test_discrete_gains_are_mutual_best_responses() -> None:
    """Each player's discrete gain is its own DP-optimal reply (single-player Riccati recursion)
    to the other's gains."""
    rng = np.random.default_rng(0)
    n, stages = 3, 6
    A = [np.eye(n) + 0.1 * rng.standard_normal((n, n)) for _ in range(stages)]
    B = [rng.standard_normal((n, 2)) for _ in range(stages)]
    N = np.zeros((n, 2))
    players = [
        LQPlayer("a", slice(0, 1), np.eye(n), N, np.diag([1.0, 0.3]), 2 * np.eye(n)),
        LQPlayer("b", slice(1, 2), np.diag([0.5, 1.0, 0.0]), N, np.diag([0.0, 1.5]), np.eye(n)),
    ]
    x0 = np.array([1.0, -0.5, 0.3])
    solution = discrete_feedback_nash(A, B, players, x0)
    for i, player in enumerate(players):
        Z = player.S
        for k in reversed(range(stages)):
            F = solution.K[k].copy()
            F[player.controls] = 0.0
            Ak, Bi = A[k] - B[k] @ F, B[k][:, player.controls]
            Rii = player.R[player.controls, player.controls]
            cross = -F.T @ player.R[:, player.controls]
            Qk = player.Q + F.T @ player.R @ F
            gain = np.linalg.solve(Rii + Bi.T @ Z @ Bi, Bi.T @ Z @ Ak + cross.T)
            np.testing.assert_allclose(gain, solution.K[k][player.controls], rtol=1e-9, atol=1e-12)
            closed = Ak - Bi @ gain
            Z = closed.T @ Z @ closed + gain.T @ Rii @ gain - cross @ gain - (cross @ gain).T + Qk
        assert 0.5 * x0 @ Z @ x0 == pytest.approx(solution.values[i], rel=1e-10)
