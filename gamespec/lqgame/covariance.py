"""Covariance steering games of section 4.4 in the gains ``K_k``, ``L_k`` of eq. 4.51.

The gains enter as ``κ = [vec K_0; …; vec K_{N-1}]`` and ``ℓ`` likewise (column-major ``vec``), so
that the block-diagonal structure of eq. 4.55 is built in and the multipliers ``Θ, Ξ`` of eq. 4.58
are not needed. The payoff eq. 4.56 is then the quadratic

``J_Σ = κᵀH_KK κ + 2κᵀH_KL ℓ + ℓᵀH_LL ℓ + 2g_Kᵀκ + 2g_Lᵀℓ + tr(Q̄ Σ_s)``,

whose blocks are the structured parts of ``Σ_s ⊗ (ℬᵀQ̄ℬ + R̄)``, ``Σ_s ⊗ ℬᵀQ̄𝒞``,
``Σ_s ⊗ (𝒞ᵀQ̄𝒞 − S̄)`` and of ``ℬᵀQ̄Σ_s``, ``𝒞ᵀQ̄Σ_s``. Its stationary point is eq. 4.59 (UCSG).
The relaxed terminal constraint eq. 4.61 reads ``‖W‖₂ ≤ 1`` (eq. 4.62) with
``vec W = w_0 + T_WK κ + T_WL ℓ``, ``W = Σ_N^{-1/2} E_N (I + ℬK + 𝒞L) F``.
:func:`algorithm_2` is Algorithm 2 on the best-response engine (:mod:`gamespec.best_response`)
with the players' best responses supplied by a backend.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property

import numpy as np
from scipy.linalg import lu_factor, lu_solve, sqrtm

from gamespec.best_response import BestResponseRun, Response, Settings, VectorPlayer, iterate
from gamespec.lqgame.lifting import Lifted
from gamespec.specs.lq_model import LQGame


def _blocks(M: np.ndarray, rows: int, cols: int, N: int) -> np.ndarray:
    """The first N×N blocks of ``M`` (block size rows × cols) as an array (N, N, rows, cols)."""
    return M[: N * rows, : N * cols].reshape(N, rows, N, cols).transpose(0, 2, 1, 3)


def _structured_hessian(H: np.ndarray, Sigma_blocks: np.ndarray, p: int, q: int) -> np.ndarray:
    """Rows/columns of ``Σ_s ⊗ H`` that touch the diagonal gain blocks: block (k, j) is
    ``Σ_s[k, j] ⊗ H[k, j]`` (``H`` with blocks p × q)."""
    N, _, n, _ = Sigma_blocks.shape
    H4 = _blocks(H, p, q, N)
    return np.einsum("kjab,kjcd->kacjbd", Sigma_blocks, H4).reshape(N * n * p, N * n * q)


def _structured_vec(G: np.ndarray, p: int, n: int, N: int) -> np.ndarray:
    """``[vec G[0, 0]; …; vec G[N-1, N-1]]`` of the diagonal p × n blocks of ``G``."""
    return np.concatenate([G[k * p : (k + 1) * p, k * n : (k + 1) * n].T.ravel() for k in range(N)])


def gains_to_vector(gains: np.ndarray) -> np.ndarray:
    """(N, p, n) gains → ``[vec G_0; …]`` (column-major vec)."""
    return gains.transpose(0, 2, 1).ravel()


def vector_to_gains(vector: np.ndarray, p: int, n: int) -> np.ndarray:
    """Inverse of :func:`gains_to_vector`."""
    return vector.reshape(-1, n, p).transpose(0, 2, 1)


def lift_gains(gains: np.ndarray) -> np.ndarray:
    """The block matrix of eq. 4.55: ``G_k`` at block (k, k), last block column zero."""
    N, p, n = gains.shape
    lifted = np.zeros((N * p, (N + 1) * n))
    for k in range(N):
        lifted[k * p : (k + 1) * p, k * n : (k + 1) * n] = gains[k]
    return lifted


class CovarianceGame:
    """The covariance steering game (eq. 4.24/4.26) of one game in vectorized gains."""

    def __init__(self, game: LQGame, lifted: Lifted) -> None:
        self.game = game
        self.lifted = lifted
        N, n, m, ell = game.N, game.n, game.m, game.ell
        Q, B, C = lifted.Q, lifted.B, lifted.C
        Sigma_blocks = _blocks(lifted.Sigma_s, n, n, N)
        self.H_KK = _structured_hessian(B.T @ Q @ B + lifted.R, Sigma_blocks, m, m)
        self.H_KL = _structured_hessian(B.T @ Q @ C, Sigma_blocks, m, ell)
        self.H_LL = _structured_hessian(C.T @ Q @ C - lifted.S, Sigma_blocks, ell, ell)
        self.g_K = _structured_vec(B.T @ Q @ lifted.Sigma_s, m, n, N)
        self.g_L = _structured_vec(C.T @ Q @ lifted.Sigma_s, ell, n, N)
        self.constant = float(np.trace(Q @ lifted.Sigma_s))

    def payoff(self, kappa: np.ndarray, ell: np.ndarray) -> float:
        """``J_Σ`` of eq. 4.56 from the quadratic form."""
        return float(
            kappa @ self.H_KK @ kappa
            + 2 * kappa @ self.H_KL @ ell
            + ell @ self.H_LL @ ell
            + 2 * self.g_K @ kappa
            + 2 * self.g_L @ ell
            + self.constant
        )

    def unconstrained_saddle(self) -> tuple[np.ndarray, np.ndarray]:
        """The UCSG stationary point: eq. 4.59 restricted to the gain structure."""
        H = np.block([[self.H_KK, self.H_KL], [self.H_KL.T, self.H_LL]])
        z = -np.linalg.solve(H, np.concatenate([self.g_K, self.g_L]))
        return z[: self.g_K.size], z[self.g_K.size :]

    @cached_property
    def _stopper_factor(self) -> tuple[np.ndarray, np.ndarray]:
        """The LU factors of ``H_LL``, computed once for every best response of the stopper."""
        return lu_factor(self.H_LL)

    def stopper_response(self, kappa: np.ndarray) -> np.ndarray:
        """The stopper's best response ``argmax_L J_Σ(K, L)`` (eq. 4.59b with K fixed)."""
        return -lu_solve(self._stopper_factor, self.g_L + self.H_KL.T @ kappa)

    def stopper_linear_term(self, kappa: np.ndarray) -> np.ndarray:
        """The stopper's linear coefficient ``g_L + H_LKκ`` given the controller's gains."""
        return self.g_L + self.H_KL.T @ kappa

    def controller_linear_term(self, ell: np.ndarray) -> np.ndarray:
        """The controller's linear coefficient ``g_K + H_KLℓ`` given the stopper's gains."""
        return self.g_K + self.H_KL @ ell

    def terminal_map(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(w_0, T_WK, T_WL)`` with ``vec W = w_0 + T_WK κ + T_WL ℓ`` (eq. 4.62)."""
        lifted, game = self.lifted, self.game
        if game.SigmaN is None:
            raise ValueError("the game has no terminal covariance")
        root_inv = np.linalg.inv(np.real(sqrtm(game.SigmaN)))
        F = lifted.blocks(lifted.F)
        BN = lifted.terminal(lifted.B).reshape(game.n, game.N, game.m)
        CN = lifted.terminal(lifted.C).reshape(game.n, game.N, game.ell)
        T_K = np.hstack([np.kron(F[k].T, root_inv @ BN[:, k]) for k in range(game.N)])
        T_L = np.hstack([np.kron(F[k].T, root_inv @ CN[:, k]) for k in range(game.N)])
        return (root_inv @ F[game.N]).T.ravel(), T_K, T_L

    def state_covariances(self, K: np.ndarray, L: np.ndarray) -> np.ndarray:
        """``Σ_k`` for k = 0…N from ``(I + ℬK + 𝒞L) Σ_s (I + ℬK + 𝒞L)ᵀ`` (eq. 4.54, 4.57), (N+1, n, n)."""
        lifted = self.lifted
        M = np.eye(lifted.Sigma_s.shape[0]) + lifted.B @ lift_gains(K) + lifted.C @ lift_gains(L)
        full = M @ lifted.Sigma_s @ M.T
        N, n = lifted.N, lifted.n
        return np.stack([full[k * n : (k + 1) * n, k * n : (k + 1) * n] for k in range(N + 1)])


STOPPER, CONTROLLER = "stopper", "controller"
"""The players' names in Algorithm 2's history."""

Step = Callable[[np.ndarray], tuple[np.ndarray | None, Response]]
"""A player's best response to the other's gains: its own gains (None when the step failed) and
how the step went."""


def algorithm_2(
    stopper_step: Step,
    controller_step: Step,
    kappa0: np.ndarray,
    ell0: np.ndarray,
    settings: Settings,
) -> BestResponseRun:
    """Algorithm 2 on the best-response engine: ``L_{i+1} = argmax_L J(K_i, L)`` (the stopper) and
    ``K_{i+1} = argmin_{K ∈ 𝒦(L_i)} J(K, L_i)`` (the controller) until ``ε_k = ‖K_{i+1} − K_i‖``
    and ``ε_ℓ = ‖L_{i+1} − L_i‖`` are both at most the tolerance (section 4.5). Jacobi is the
    thesis' scheme; Gauss–Seidel lets the controller answer ``L_{i+1}``. A step that fails (e.g.
    the controller's set ``𝒦(L_i)`` is empty) stops the run with that step's status, keeping the
    best iterate (the smallest residual); a run that cycles or diverges says so (``settings``' stopping rule).
    """
    players = [
        VectorPlayer(STOPPER, lambda others: stopper_step(others[CONTROLLER])),
        VectorPlayer(CONTROLLER, lambda others: controller_step(others[STOPPER])),
    ]
    return iterate(players, {STOPPER: ell0, CONTROLLER: kappa0}, settings)
