"""The linearized dynamics along the nominal paths and their zero-order-hold discretization
(eqs. 5.5–5.8), and the lifted matrices of eq. 5.10 from the chapter-4 code.

``A(t) = ∂f/∂x(x̂(t))`` (eq. 5.6), ``r(t) = f(x̂(t)) − A(t) x̂(t)``, ``D(t) = g(x̂(t))`` per agent. Over
each step ``[τ_k, τ_{k+1}]`` the integrals of eq. 5.8 are the solutions at ``τ_{k+1}`` of
``Φ' = AΦ, Φ(τ_k) = I`` (5.8a); ``Z' = AZ + I, Z(τ_k) = 0`` (5.8b, with ``B(t) = I`` since the
control is the velocity, eq. 5.1); ``z' = Az + r, z(τ_k) = 0`` (5.8c); ``P' = AP + PAᵀ + DDᵀ,
P(τ_k) = 0`` (5.8d). All steps of both agents are integrated at once by RK4 with ``substeps`` steps
per interval. The augmented model stacks the pursuer then the evader (eq. 5.5), block-diagonal.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.linalg import block_diag

from gamespec.flowfield.field import FlowField
from gamespec.flowfield.nominal import NominalPaths
from gamespec.lqgame.lifting import lift
from gamespec.specs.lq_model import LQGame


@dataclass(frozen=True)
class DiscreteModel:
    """``x_{k+1} = A_k x_k + B_k u_k + r_k + D_k w_k`` (eq. 5.7): ``A, B, DD`` (N, 4, 4), ``r``
    (N, 4), ``D`` (N, 4, 4) a symmetric square root of ``DD``; ``step`` is ``T̂/N``."""

    A: np.ndarray
    B: np.ndarray
    r: np.ndarray
    DD: np.ndarray
    D: np.ndarray
    step: float

    @property
    def N(self) -> int:
        return self.A.shape[0]


def _symmetric_root(M: np.ndarray) -> np.ndarray:
    w, v = np.linalg.eigh((M + np.swapaxes(M, -1, -2)) / 2)
    return np.einsum("...ij,...j,...kj->...ik", v, np.sqrt(np.clip(w, 0.0, None)), v)


def zero_order_hold(field: FlowField, paths: NominalPaths, steps: int, substeps: int = 16) -> DiscreteModel:
    """Eq. 5.8 on ``τ_k = k T̂/N`` for both agents, by RK4 on the matrix ODEs above."""
    h = paths.final_time / steps
    tau = h * np.arange(steps)

    def coefficients(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        x = paths.position(t)  # (2, N, 2)
        A = field.jacobian(x)
        r = field.drift(x) - np.einsum("...ij,...j->...i", A, x)
        g = field.diffusion(x)
        return A, r, g @ np.swapaxes(g, -1, -2)

    def rate(t: np.ndarray, state: tuple[np.ndarray, ...]) -> tuple[np.ndarray, ...]:
        Phi, Z, z, P = state
        A, r, GG = coefficients(t)
        AP = A @ P
        return (
            A @ Phi,
            A @ Z + np.eye(2),
            np.einsum("...ij,...j->...i", A, z) + r,
            AP + np.swapaxes(AP, -1, -2) + GG,
        )

    shape = (2, steps)
    state = (
        np.broadcast_to(np.eye(2), (*shape, 2, 2)),
        np.zeros((*shape, 2, 2)),
        np.zeros((*shape, 2)),
        np.zeros((*shape, 2, 2)),
    )
    dt = h / substeps
    for j in range(substeps):
        t = tau + j * dt
        k1 = rate(t, state)
        k2 = rate(t + dt / 2, tuple(s + dt / 2 * k for s, k in zip(state, k1, strict=True)))
        k3 = rate(t + dt / 2, tuple(s + dt / 2 * k for s, k in zip(state, k2, strict=True)))
        k4 = rate(t + dt, tuple(s + dt * k for s, k in zip(state, k3, strict=True)))
        state = tuple(
            s + dt / 6 * (a + 2 * b + 2 * c + d) for s, a, b, c, d in zip(state, k1, k2, k3, k4, strict=True)
        )
    Phi, Z, z, P = state

    def augmented(blocks: np.ndarray) -> np.ndarray:
        return np.stack([block_diag(blocks[0, k], blocks[1, k]) for k in range(steps)])

    DD = augmented(P)
    return DiscreteModel(
        A=augmented(Phi),
        B=augmented(Z),
        r=np.concatenate([z[0], z[1]], axis=-1),
        DD=DD,
        D=_symmetric_root(DD),
        step=h,
    )


@dataclass(frozen=True)
class LiftedModel:
    """Eq. 5.9–5.10: ``X = [x_1 … x_N] = 𝒜 x₀ + ℬ U + ℛ + 𝒟 W``; ``D_y`` maps W to
    ``Y = [y_0 … y_{N−1}]`` of eq. 5.28–5.29 (``y_0 = 0``, ``y_k`` the first ``k`` noise terms)."""

    A: np.ndarray
    B: np.ndarray
    R: np.ndarray
    D: np.ndarray
    D_y: np.ndarray
    x0: np.ndarray

    def mean(self, V: np.ndarray) -> np.ndarray:
        """``X̄ = 𝒜 x₀ + ℬ V + ℛ`` (eq. 5.31a)."""
        return self.A @ self.x0 + self.B @ V + self.R


def lifted(model: DiscreteModel, x0: np.ndarray) -> LiftedModel:
    """Eq. 5.10 by the chapter-4 lifting (:func:`gamespec.lqgame.lifting.lift`, eq. 4.6), with the
    affine term ``r_k`` as an input of constant value 1; chapter 4 stacks ``x_0 … x_N``, so the first
    block row is dropped for X and the last for Y."""
    N, n = model.N, 4
    game = LQGame(
        A=model.A,
        B=model.B,
        C=model.r[:, :, None],
        D=model.D,
        Q=np.zeros((N, n, n)),
        R=np.broadcast_to(np.eye(n), (N, n, n)),
        S=np.ones((N, 1, 1)),
        mu0=np.asarray(x0, dtype=float),
        Sigma0=np.zeros((n, n)),
    )
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Matrix is singular")  # Σ₀ = 0: x₀ is known
        chapter4 = lift(game)
    return LiftedModel(
        A=chapter4.A[n:],
        B=chapter4.B[n:],
        R=chapter4.C[n:] @ np.ones(N),
        D=chapter4.D[n:],
        D_y=chapter4.D[: N * n],
        x0=np.asarray(x0, dtype=float),
    )
