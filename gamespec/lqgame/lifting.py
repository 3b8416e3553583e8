"""The lifted ("script") matrices of eq. 4.6, built once per game.

``X = [x_0; …; x_N] = 𝒜 x_0 + ℬ U + 𝒞 V + 𝒟 W`` with ``U = [u_0; …; u_{N-1}]`` (likewise V, W),
and the block-diagonal weights ``Q̄ = blkdiag(Q_0, …, Q_{N-1}, 0)``, ``R̄``, ``S̄`` of eq. 4.7.
``Sigma_s = 𝒜 Σ_0 𝒜ᵀ + 𝒟 𝒟ᵀ`` (section 4.4) is the covariance of the noise-only state ``Y`` of
eq. 4.53; ``F = [𝒜 Σ_0^{1/2}, 𝒟]`` is a factor with ``F Fᵀ = Sigma_s``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import block_diag, sqrtm

from gamespec.specs.lq_model import LQGame


@dataclass(frozen=True)
class Lifted:
    """Eq. 4.6 and 4.7 for one game; ``terminal(M)`` is ``E_N M`` (eq. 4.11)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    F: np.ndarray
    Sigma_s: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    S: np.ndarray
    N: int
    n: int

    def terminal(self, M: np.ndarray) -> np.ndarray:
        """Rows of the final step ``E_N M``."""
        return M[self.N * self.n :]

    def blocks(self, M: np.ndarray) -> np.ndarray:
        """The (N+1) row blocks of ``M`` as an array (N+1, n, cols)."""
        return M.reshape(self.N + 1, self.n, -1)


def _lift_input(game: LQGame, inputs: np.ndarray) -> np.ndarray:
    """Block (k, j) = Φ(k, j+1) G_j for j < k, where Φ(k, j) = A_{k-1} ⋯ A_j."""
    N, n, w = inputs.shape
    lifted = np.zeros((N + 1, n, N, w))
    for k in range(1, N + 1):
        lifted[k, :, : k - 1] = np.einsum("ab,bjc->ajc", game.A[k - 1], lifted[k - 1, :, : k - 1])
        lifted[k, :, k - 1] = inputs[k - 1]
    return lifted.reshape((N + 1) * n, N * w)


def lift(game: LQGame) -> Lifted:
    """The lifted matrices of eq. 4.6 and weights of eq. 4.7."""
    N, n = game.N, game.n
    transition = np.zeros((N + 1, n, n))
    transition[0] = np.eye(n)
    for k in range(N):
        transition[k + 1] = game.A[k] @ transition[k]
    A = transition.reshape((N + 1) * n, n)
    D = _lift_input(game, game.D)
    root0 = np.real(sqrtm(game.Sigma0))
    return Lifted(
        A=A,
        B=_lift_input(game, game.B),
        C=_lift_input(game, game.C),
        D=D,
        Q=block_diag(*game.Q, np.zeros((n, n))),
        R=block_diag(*game.R),
        S=block_diag(*game.S),
        Sigma_s=A @ game.Sigma0 @ A.T + D @ D.T,
        F=np.hstack([A @ root0, D]),
        N=N,
        n=n,
    )
