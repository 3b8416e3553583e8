"""Props. 7–8: the game separates into a mean game and a covariance game.

The total expected payoff eq. 4.4 of affine strategies ``u = ū + K y``, ``v = v̄ + L y`` is computed
here independently of the lifted formulas, by propagating the first and second moments of the
augmented state ``(x, y)`` step by step. Solved jointly over ``(Ū, K)`` and ``(V̄, L)``, it gives the
same saddle point as Prop. 9 and eq. 4.59 solved separately; under the terminal constraints, the
mean does not depend on the noise and the gains do not depend on the mean target.
"""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.lqgame.covariance import vector_to_gains
from gamespec.lqgame.solution import GameModel
from gamespec.specs.lq_model import LQGame
from tests.conftest import PROBLEMS
from tests.lqgame.conftest import random_game


def total_payoff(game: LQGame, U: np.ndarray, V: np.ndarray, K: np.ndarray, L: np.ndarray) -> float:
    """``E[Σ x_kᵀQ_k x_k + u_kᵀR_k u_k − v_kᵀS_k v_k]`` by moment propagation of ``(x, y)``."""
    n = game.n
    mean = np.concatenate([game.mu0, np.zeros(n)])
    cov = np.block([[game.Sigma0, game.Sigma0], [game.Sigma0, game.Sigma0]])
    total = 0.0
    for k in range(game.N):
        mx, Pxx, Pyy = mean[:n], cov[:n, :n], cov[n:, n:]
        total += float(np.trace(game.Q[k] @ (Pxx + np.outer(mx, mx))))
        total += float(U[k] @ game.R[k] @ U[k] + np.trace(K[k].T @ game.R[k] @ K[k] @ Pyy))
        total -= float(V[k] @ game.S[k] @ V[k] + np.trace(L[k].T @ game.S[k] @ L[k] @ Pyy))
        Phi = np.block([[game.A[k], game.B[k] @ K[k] + game.C[k] @ L[k]], [np.zeros((n, n)), game.A[k]]])
        G = np.vstack([game.D[k], game.D[k]])
        mean = Phi @ mean + np.concatenate([game.B[k] @ U[k] + game.C[k] @ V[k], np.zeros(n)])
        cov = Phi @ cov @ Phi.T + G @ G.T
    return total


class Joint:
    """The total payoff as a function of all decision variables ``z = (Ū, κ, V̄, ℓ)``."""

    def __init__(self, game: LQGame) -> None:
        self.game = game
        N, n, m, ell = game.N, game.n, game.m, game.ell
        self.sizes = [N * m, N * m * n, N * ell, N * ell * n]

    def __call__(self, z: np.ndarray) -> float:
        g = self.game
        U, kappa, V, ell = np.split(z, np.cumsum(self.sizes)[:-1])
        return total_payoff(
            g,
            U.reshape(g.N, g.m),
            V.reshape(g.N, g.ell),
            vector_to_gains(kappa, g.m, g.n),
            vector_to_gains(ell, g.ell, g.n),
        )

    def stationary_point(self) -> tuple[np.ndarray, np.ndarray]:
        """Gradient and Hessian by central differences (exact for a quadratic), then ``H z = −∇``."""
        eye = np.eye(sum(self.sizes))
        grad = np.array([(self(e) - self(-e)) / 2 for e in eye])
        hess = np.array(
            [[(self(a + b) - self(a - b) - self(b - a) + self(-a - b)) / 4 for b in eye] for a in eye]
        )
        return -np.linalg.solve(hess, grad), hess


def test_total_payoff_is_mean_plus_covariance_payoff():
    """eq. 4.20: ``J = J_μ(Ū, V̄) + J_Σ(K, L)`` for any strategies."""
    game = random_game(7, N=3, n=2, m=1, ell=1, r=1)
    model = GameModel.build(game)
    joint = Joint(game)
    z = np.random.default_rng(0).standard_normal(sum(joint.sizes))
    U, kappa, V, ell = np.split(z, np.cumsum(joint.sizes)[:-1])
    separate = model.mean.payoff(U, V) + model.covariance.payoff(kappa, ell)
    assert joint(z) == pytest.approx(separate, rel=1e-9)


def test_joint_saddle_point_is_the_separate_one():
    """Prop. 7: the stationary point of the total payoff over all variables is Prop. 9's mean saddle
    point together with eq. 4.59's gains, and the Hessian has no mean–gain coupling."""
    game = random_game(8, N=3, n=2, m=1, ell=1, r=1)
    model = GameModel.build(game)
    joint = Joint(game)
    z, hess = joint.stationary_point()
    U, kappa, V, ell = np.split(z, np.cumsum(joint.sizes)[:-1])
    U_star, V_star = model.mean.saddle_point()
    kappa_star, ell_star = model.covariance.unconstrained_saddle()
    np.testing.assert_allclose(np.concatenate([U, V]), np.concatenate([U_star, V_star]), atol=1e-6)
    np.testing.assert_allclose(
        np.concatenate([kappa, ell]), np.concatenate([kappa_star, ell_star]), atol=1e-6
    )
    mean_idx = np.r_[0 : joint.sizes[0], sum(joint.sizes[:2]) : sum(joint.sizes[:3])]
    gain_idx = np.setdiff1d(np.arange(hess.shape[0]), mean_idx)
    assert np.abs(hess[np.ix_(mean_idx, gain_idx)]).max() <= 1e-7 * np.abs(hess).max()


def test_constrained_game_separates():
    """Prop. 8 on §4.5.1: the mean steering does not see the noise, the gains do not see the mean
    target, and the reported objective is the total payoff of the returned strategies."""
    path = PROBLEMS / "ch4" / "test_example.yaml"
    base = gamespec.solve(gamespec.load(path))
    moved = gamespec.solve(gamespec.load(path, ["problem.terminal.mean=[1, -1, 0, 0]"]))
    noisier = gamespec.solve(gamespec.load(path, ["problem.parameters.noise=0.005"]))
    for r in (base, moved, noisier):
        assert r.ok, r.message
    np.testing.assert_allclose(moved.arrays["K"], base.arrays["K"], atol=1e-6)
    np.testing.assert_allclose(moved.arrays["L"], base.arrays["L"], atol=1e-6)
    np.testing.assert_allclose(noisier.arrays["mean"], base.arrays["mean"], atol=1e-9)
    game = gamespec.load(path).game()
    U = np.column_stack([base.controls["u1"], base.controls["u2"]])
    V = np.column_stack([base.controls["v1"], base.controls["v2"]])
    expected = total_payoff(game, U, V, base.arrays["K"], base.arrays["L"])
    assert base.objective == pytest.approx(expected, rel=1e-9)
