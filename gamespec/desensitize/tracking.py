"""LQR tracking of a nominal trajectory under parameter errors (eqs. 6.27-6.29).

The cost ``½‖Δx(t_f)‖² + ∫ Δuᵀ Δu dt`` is ``½ Δx(t_f)ᵀ P_f Δx(t_f) + ½ ∫ Δuᵀ R Δu`` with
``P_f = I`` and ``R = 2I``; along the nominal, ``A(t) = f_x`` and ``B(t) = f_u`` (eq. 6.29) at
``ρ̂``, and the time-varying Riccati equation ``-Ṗ = AᵀP + PA - P B R⁻¹ Bᵀ P`` (no state weight)
gives the gain ``K = R⁻¹ Bᵀ P`` and the feedback ``Δu = -K Δx``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from gamespec.desensitize.simulate import Trajectories, Values
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.symbolic.calculus import linearize
from gamespec.symbolic.language import TIME

CONTROL_WEIGHT = 2.0
"""R of eq. 6.27 written as ½ Δuᵀ R Δu (the integrand is Δu² without the ½)."""


def linearization(
    ocp: SymbolicOcp, nominal: Trajectories, params: Values, inputs: Callable[[np.ndarray], np.ndarray] | None
) -> tuple[np.ndarray, np.ndarray]:
    """``A(t)`` (steps+1, n, n) and ``B(t)`` (steps+1, n, m) along the nominal (eq. 6.29); grid
    inputs enter as further columns of the input matrix, dropped from ``B``."""
    m = len(ocp.u)
    controls = nominal.u[:, :, 0]
    if inputs is not None:
        controls = np.hstack([controls, np.asarray(inputs(nominal.t)).T])
    A, B = linearize(
        ocp.dynamics, ocp.x, [*ocp.u, *ocp.w], nominal.x[:, :, 0], controls, dict(params), (TIME, nominal.t)
    )
    return A, B[:, :, :m]


def riccati_gains(t: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Gains ``K(t_k)`` (steps+1, m, n) from the Riccati equation integrated backward by RK4 from
    ``P(t_f) = I`` (coefficients at a step's midpoint: the mean of its ends)."""
    n = A.shape[1]
    r_inv = 1.0 / CONTROL_WEIGHT

    def minus_pdot(P: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return a.T @ P + P @ a - r_inv * P @ b @ b.T @ P

    P = np.eye(n)
    K = np.empty((len(t), B.shape[2], n))
    K[-1] = r_inv * B[-1].T @ P
    for k in range(len(t) - 1, 0, -1):
        h = t[k] - t[k - 1]
        am, bm = 0.5 * (A[k] + A[k - 1]), 0.5 * (B[k] + B[k - 1])
        k1 = minus_pdot(P, A[k], B[k])
        k2 = minus_pdot(P + h / 2 * k1, am, bm)
        k3 = minus_pdot(P + h / 2 * k2, am, bm)
        k4 = minus_pdot(P + h * k3, A[k - 1], B[k - 1])
        P = P + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        K[k - 1] = r_inv * B[k - 1].T @ P
    return K
