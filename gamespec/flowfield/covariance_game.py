"""The chance-constrained covariance game of section 5.3 (eqs. 5.27–5.36) as arrays.

Controls ``U = V + K Y`` (eq. 5.30) with ``K = blkdiag(K_0 … K_{N−1})``, ``K_k`` 4 × 4, the rows of
player ``i`` (pursuer rows 0–1, evader rows 2–3) chosen by that player: its gains ``κⁱ`` (N, 2, 4)
and feedforward ``Vⁱ`` (N, 2). Since ``y_0 = 0`` (eq. 5.28), ``K_0`` has no effect and is fixed to 0.

Indexing (an ambiguity of the thesis resolved): eq. 5.29 writes ``Y = 𝒟W`` with the ``𝒟`` of
eq. 5.10, which maps W to ``[x_1 … x_N]``; with ``y_0 = 0`` and ``y_{k+1} = A_k y_k + D_k w_k`` the
stacked ``Y = [y_0 … y_{N−1}]`` is that map shifted one step, ``Y = 𝒟_y W``. So the error of eq.
5.31b is ``X̃ = (𝒟 + ℬ K 𝒟_y) W`` (causal: ``u_k`` sees the noise up to step k−1 only), and
``Σˣ = M Mᵀ`` with ``M = 𝒟 + ℬ K 𝒟_y`` (eq. 5.33b). With ``Δ = Eᵖ − Eᵉ`` (eq. 5.11), the relative
factor is ``G = Δ M`` and ``Σʳ = G Gᵀ`` (eq. 5.33c); ``vec G`` is affine in the gains,
``vec G = g₀ + Tᵖ κᵖ + Tᵉ κᵉ``.

Payoffs (another ambiguity): eq. 5.17 is ``‖Σʳ‖²_F = ‖G Gᵀ‖²_F`` (``"frobenius"``), while eq. 5.34,
which claims to rewrite it, is ``tr(Δᵀ Δ Σˣ) = tr Σʳ = ‖G‖²_F`` (``"trace"``); the two are not
equal. Both are offered; both are convex in the gains, so the pursuer's step is convex and the
evader's maximizes a convex function.

Feedforward: ``J`` does not depend on ``V``, but the capture probability (eq. 5.39) does, through the
mean. With ``"free"`` each player's ``V`` ranges over eq. 5.35; nothing in ``J`` keeps it on ``Û``,
and a player moves it to free speed for its gains (eq. 5.36), shifting the mean relative position
by up to ``δ_xᵖ + δ_xᵉ``. With ``"nominal"``, ``V = Û`` (section 5.3: "the mean trajectory is
assumed to be essentially driven by … the nominal control inputs"): the means stay on the nominal
paths, open and closed loop share them, and the feedback alone is compared.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import numpy as np

from gamespec.flowfield.linearize import LiftedModel

Payoff = Literal["trace", "frobenius"]
Feedforward = Literal["free", "nominal"]
PLAYERS = ("pursuer", "evader")


@dataclass(frozen=True)
class PlayerBounds:
    """One player's limits: ``v_max`` (eq. 5.2), ``δ_x``, ``δ_u`` (eq. 5.35) and ``β`` (eq. 5.36)."""

    max_speed: float
    delta_x: float
    delta_u: float
    beta: float

    @property
    def chance_factor(self) -> float:
        """``√(2 log(1/β))`` of eq. 5.36 (Theorem 5)."""
        return float(np.sqrt(2 * np.log(1 / self.beta)))


@dataclass(frozen=True)
class Strategy:
    """One player's ``V`` (N, 2) and gains ``κ`` (N, 2, 4), ``κ[0] = 0``."""

    V: np.ndarray
    kappa: np.ndarray


@dataclass(frozen=True)
class CovarianceGame:
    """The game about the nominal ``X̂`` (N, 4) and ``Û`` (N, 4) of both players."""

    model: LiftedModel
    X_hat: np.ndarray
    U_hat: np.ndarray
    bounds: tuple[PlayerBounds, PlayerBounds]
    payoff: Payoff = "trace"
    feedforward: Feedforward = "free"

    @property
    def N(self) -> int:
        return self.X_hat.shape[0]

    @cached_property
    def delta(self) -> np.ndarray:
        """``Eᵖ − Eᵉ`` (2N × 4N) of eq. 5.11."""
        N = self.N
        E = np.zeros((N, 2, N, 4))
        for k in range(N):
            E[k, :, k, :2] = np.eye(2)
            E[k, :, k, 2:] = -np.eye(2)
        return E.reshape(2 * N, 4 * N)

    @cached_property
    def g0(self) -> np.ndarray:
        """``vec(Δ 𝒟)``: the relative factor without feedback."""
        return (self.delta @ self.model.D).reshape(-1)

    @cached_property
    def noise_rows(self) -> np.ndarray:
        """``𝒟_y`` per step, (N, 4, 4N): ``y_k = noise_rows[k] W``."""
        return self.model.D_y.reshape(self.N, 4, -1)

    @cached_property
    def control_map(self) -> np.ndarray:
        """``Δ ℬ`` as (2N, N, 4): the relative positions' response to each step's controls."""
        return (self.delta @ self.model.B).reshape(2 * self.N, self.N, 4)

    def gain_map(self, player: int) -> np.ndarray:
        """``Tⁱ`` with ``vec G = g₀ + Tᵖ vec κᵖ + Tᵉ vec κᵉ``: (2N·4N, N·8)."""
        N = self.N
        DB = self.control_map.reshape(2 * N, N, 2, 2)[:, :, player, :]
        T = np.einsum("rka,kbc->rckab", DB, self.noise_rows)
        return np.ascontiguousarray(T.reshape(2 * N * 4 * N, N * 8))

    @cached_property
    def gain_maps(self) -> tuple[np.ndarray, np.ndarray]:
        return self.gain_map(0), self.gain_map(1)

    def factor(self, strategies: tuple[Strategy, Strategy]) -> np.ndarray:
        """``G = Δ𝒟 + Δℬ K 𝒟_y`` (2N × 4N) with ``Σʳ = G Gᵀ``, step by step (``K`` block-diagonal)."""
        K = np.concatenate([s.kappa for s in strategies], axis=1)
        gained = np.einsum("kab,kbc->kac", K, self.noise_rows)
        return self.g0.reshape(2 * self.N, -1) + np.einsum("rka,kac->rc", self.control_map, gained)

    def value(self, strategies: tuple[Strategy, Strategy]) -> float:
        """The payoff ``J`` (eq. 5.34 ``"trace"`` or eq. 5.17 ``"frobenius"``)."""
        G = self.factor(strategies)
        if self.payoff == "trace":
            return float(np.sum(G * G))
        return float(np.sum((G @ G.T) ** 2))

    def gradient(self, strategies: tuple[Strategy, Strategy], player: int) -> np.ndarray:
        """``∂J/∂κⁱ`` as (N, 2, 4)."""
        G = self.factor(strategies)
        dG = 2 * G if self.payoff == "trace" else 4 * (G @ G.T) @ G
        rows = self.control_map[:, :, 2 * player : 2 * player + 2]
        return np.einsum("rka,rc,kbc->kab", rows, dG, self.noise_rows, optimize=True)

    def nominal(self) -> tuple[Strategy, Strategy]:
        """Open loop: ``V = Û``, ``K = 0``."""
        return tuple(
            Strategy(self.U_hat[:, 2 * i : 2 * i + 2].copy(), np.zeros((self.N, 2, 4))) for i in range(2)
        )

    def controls(self, strategies: tuple[Strategy, Strategy]) -> tuple[np.ndarray, np.ndarray]:
        """The augmented ``V`` (N, 4) and ``K_k`` (N, 4, 4)."""
        return np.concatenate([s.V for s in strategies], axis=1), np.concatenate(
            [s.kappa for s in strategies], axis=1
        )

    def mean(self, strategies: tuple[Strategy, Strategy]) -> np.ndarray:
        """``X̄`` (N, 4) by eq. 5.31a."""
        V, _ = self.controls(strategies)
        return self.model.mean(V.reshape(-1)).reshape(self.N, 4)

    def relative(self, strategies: tuple[Strategy, Strategy]) -> tuple[np.ndarray, np.ndarray]:
        """``μʳ_k`` (N, 2) and ``Σʳ_k`` (N, 2, 2) for k = 1 … N (eq. 5.12, 5.33c)."""
        X = self.mean(strategies)
        G = self.factor(strategies).reshape(self.N, 2, -1)
        return X[:, :2] - X[:, 2:], G @ np.swapaxes(G, 1, 2)

    def mean_map(self, player: int) -> tuple[np.ndarray, np.ndarray]:
        """``(c, B)`` with player i's mean positions ``X̄ⁱ = c + B vec Vⁱ`` (N·2), the dynamics
        being block-diagonal in the players (eq. 5.5)."""
        N = self.N
        rows = (4 * np.arange(N)[:, None] + 2 * player + np.arange(2)).reshape(-1)
        c = (self.model.A @ self.model.x0 + self.model.R)[rows]
        return c, self.model.B[np.ix_(rows, rows)]

    def violations(self, strategies: tuple[Strategy, Strategy]) -> dict[str, float]:
        """The largest excess over each bound of eqs. 5.35–5.36, per player (≤ 0 when feasible)."""
        X = self.mean(strategies)
        out: dict[str, float] = {}
        for i, (name, s, b) in enumerate(zip(PLAYERS, strategies, self.bounds, strict=True)):
            spread = np.linalg.norm(np.einsum("kab,kbc->kac", s.kappa, self.noise_rows), axis=(1, 2))
            out[f"{name}_mean_deviation"] = float(
                np.max(np.linalg.norm(X[:, 2 * i : 2 * i + 2] - self.X_hat[:, 2 * i : 2 * i + 2], axis=1))
                - b.delta_x
            )
            out[f"{name}_control_deviation"] = float(
                np.max(np.linalg.norm(s.V - self.U_hat[:, 2 * i : 2 * i + 2], axis=1)) - b.delta_u
            )
            out[f"{name}_chance"] = float(
                np.max(np.linalg.norm(s.V, axis=1) + b.chance_factor * spread) - b.max_speed
            )
        return out
