"""The lifted matrices of eq. 4.6 against the step-by-step recursion eq. 4.1, and the
zero-order hold of eq. 4.70 against scipy's discretization."""

from __future__ import annotations

import numpy as np
from scipy.signal import cont2discrete

from gamespec.lqgame.game import zero_order_hold
from gamespec.lqgame.lifting import lift
from tests.lqgame.conftest import random_game


def test_lifted_matrices_reproduce_the_recursion():
    game = random_game(3, N=5)
    lifted = lift(game)
    rng = np.random.default_rng(0)
    x0 = rng.standard_normal(game.n)
    U, V, W = (rng.standard_normal((game.N, w)) for w in (game.m, game.ell, game.r))
    x = [x0]
    for k in range(game.N):
        x.append(game.A[k] @ x[-1] + game.B[k] @ U[k] + game.C[k] @ V[k] + game.D[k] @ W[k])
    X = lifted.A @ x0 + lifted.B @ U.ravel() + lifted.C @ V.ravel() + lifted.D @ W.ravel()
    np.testing.assert_allclose(X, np.concatenate(x), atol=1e-12)


def test_noise_state_covariance_factor():
    """``F Fᵀ = Σ_s = 𝒜Σ_0𝒜ᵀ + 𝒟𝒟ᵀ`` (section 4.4)."""
    lifted = lift(random_game(4))
    np.testing.assert_allclose(lifted.F @ lifted.F.T, lifted.Sigma_s, atol=1e-12)


def test_zero_order_hold_matches_scipy():
    rng = np.random.default_rng(1)
    A = rng.standard_normal((4, 4))
    B, C = rng.standard_normal((4, 2)), rng.standard_normal((4, 1))
    Ad, (Bd, Cd) = zero_order_hold(A, [B, C], 0.1)
    ref = cont2discrete((A, np.hstack([B, C]), np.eye(4), np.zeros((4, 3))), 0.1, method="zoh")
    np.testing.assert_allclose(Ad, ref[0], atol=1e-12)
    np.testing.assert_allclose(np.hstack([Bd, Cd]), ref[1], atol=1e-12)
