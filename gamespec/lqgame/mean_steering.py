"""Mean steering games of section 4.3: the unconstrained saddle point and the controller's upper game.

With ``H_uu = ℬᵀQ̄ℬ + R̄``, ``H_uv = ℬᵀQ̄𝒞`` and ``H_vv = 𝒞ᵀQ̄𝒞 − S̄`` (eq. 4.32), the stopper's best
response to ``Ū`` is eq. 4.39b; substituting it leaves the controller the quadratic
``Ūᵀ ℛ Ū − 2 ℳᵀ Ū + const`` (eq. 4.46a–b) subject to ``𝒢 Ū = h`` (eq. 4.42). :func:`upper_game_qp`
gives that QP for any QP solver; :func:`saddle_point` (Prop. 9) and :func:`upper_game` (Prop. 10)
are the closed forms.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from gamespec.lqgame.lifting import Lifted
from gamespec.specs.lq_model import LQGame


@dataclass(frozen=True)
class QPData:
    """``min ½ zᵀ P z + qᵀ z`` subject to ``A z = b`` (no equality when ``A`` is None)."""

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray | None = None
    b: np.ndarray | None = None


class MeanGame:
    """The lifted mean game of eq. 4.23/4.25 for one game."""

    def __init__(self, game: LQGame, lifted: Lifted) -> None:
        self.game = game
        self.lifted = lifted
        Q = lifted.Q
        self.H_uu = lifted.B.T @ Q @ lifted.B + lifted.R
        self.H_uv = lifted.B.T @ Q @ lifted.C
        self.H_vv = lifted.C.T @ Q @ lifted.C - lifted.S
        self.free_u = lifted.B.T @ Q @ lifted.A @ game.mu0
        self.free_v = lifted.C.T @ Q @ lifted.A @ game.mu0

    @cached_property
    def _response(self) -> tuple[np.ndarray, np.ndarray]:
        """``V̄ = Γ Ū + γ`` (eq. 4.39b)."""
        solve = np.linalg.solve(self.H_vv, np.column_stack([self.H_uv.T, self.free_v]))
        return -solve[:, :-1], -solve[:, -1]

    def stopper_response(self, U: np.ndarray) -> np.ndarray:
        """The stopper's best response to ``Ū`` (eq. 4.39b)."""
        gain, offset = self._response
        return gain @ U + offset

    @cached_property
    def reduced(self) -> tuple[np.ndarray, np.ndarray]:
        """``ℛ`` (eq. 4.46a) and ``ℳ`` (eq. 4.46b)."""
        gain, offset = self._response
        calR = self.H_uu + self.H_uv @ gain
        calM = -(self.free_u + self.H_uv @ offset)
        return calR, calM

    @cached_property
    def relative_controllability(self) -> tuple[np.ndarray, np.ndarray]:
        """``𝒢`` of eq. 4.40 and the drift ``(Ā_N − C̄_N H_vv⁻¹ 𝒞ᵀQ̄𝒜) μ_0`` of eq. 4.42."""
        gain, offset = self._response
        BN = self.lifted.terminal(self.lifted.B)
        CN = self.lifted.terminal(self.lifted.C)
        G = BN + CN @ gain
        drift = self.lifted.terminal(self.lifted.A) @ self.game.mu0 + CN @ offset
        return G, drift

    def target_equation(self) -> tuple[np.ndarray, np.ndarray]:
        """Eq. 4.42 ``𝒢 Ū = μ_N − drift`` on the rows of ``μ_N`` that are given (not NaN)."""
        if self.game.muN is None:
            raise ValueError("the game has no terminal mean")
        G, drift = self.relative_controllability
        rows = ~np.isnan(self.game.muN)
        return G[rows], self.game.muN[rows] - drift[rows]

    def upper_game_qp(self) -> QPData:
        """The controller's upper game eq. 4.43 as a QP in ``Ū`` (equality eq. 4.42 if ``μ_N`` given)."""
        calR, calM = self.reduced
        P = calR + calR.T
        if self.game.muN is None:
            return QPData(P=P, q=-2 * calM)
        G, target = self.target_equation()
        return QPData(P=P, q=-2 * calM, A=G, b=target)

    def saddle_point(self) -> tuple[np.ndarray, np.ndarray]:
        """The unconstrained saddle point of Prop. 9, eq. 4.28."""
        T = np.block([[self.H_uu, self.H_uv], [self.H_uv.T, self.H_vv]])
        z = -np.linalg.solve(T, np.concatenate([self.free_u, self.free_v]))
        split = self.H_uu.shape[0]
        return z[:split], z[split:]

    def upper_game(self) -> tuple[np.ndarray, np.ndarray]:
        """The constrained upper game of Prop. 10, eq. 4.45–4.46 (``λ`` by least squares when ``𝒢``
        is rank deficient but the target is reachable, Lemma 11)."""
        if self.game.muN is None:
            return self.saddle_point()
        calR, calM = self.reduced
        G, target = self.target_equation()
        Rinv_M = np.linalg.solve(calR, calM)
        Rinv_Gt = np.linalg.solve(calR, G.T)
        lam = 2 * np.linalg.lstsq(G @ Rinv_Gt, target - G @ Rinv_M, rcond=None)[0]
        U = Rinv_M + Rinv_Gt @ lam / 2
        return U, self.stopper_response(U)

    def trajectory(self, U: np.ndarray, V: np.ndarray) -> np.ndarray:
        """The mean state ``X̄`` of eq. 4.18 as an array (N+1, n)."""
        lifted = self.lifted
        X = lifted.A @ self.game.mu0 + lifted.B @ U + lifted.C @ V
        return X.reshape(lifted.N + 1, lifted.n)

    def payoff(self, U: np.ndarray, V: np.ndarray) -> float:
        """``J_μ`` of eq. 4.21."""
        X = self.trajectory(U, V).ravel()
        lifted = self.lifted
        return float(X @ lifted.Q @ X + U @ lifted.R @ U - V @ lifted.S @ V)
