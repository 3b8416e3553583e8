"""The lifted matrices of eq. 4.6 against the step-by-step recursion eq. 4.1 (for any sizes), and the
zero-order hold of eq. 4.70 against scipy's discretization."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.signal import cont2discrete

from gamespec.lqgame.lifting import lift
from gamespec.specs.lq_model import zero_order_hold
from tests.lqgame.conftest import random_game


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**16),
    N=st.integers(1, 6),
    n=st.integers(1, 4),
    m=st.integers(1, 3),
    ell=st.integers(1, 3),
    r=st.integers(1, 3),
)
def test_lifted_matrices_reproduce_the_recursion(seed: int, N: int, n: int, m: int, ell: int, r: int):
    game = random_game(seed, N=N, n=n, m=m, ell=ell, r=r)
    lifted = lift(game)
    rng = np.random.default_rng(seed)
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
