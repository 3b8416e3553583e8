"""The discrete-time linear-quadratic stochastic game of eq. 4.1 as plain arrays, and its strategies.

``x_{k+1} = A_k x_k + B_k u_k + C_k v_k + D_k w_k`` (eq. 4.1) with ``w_k`` unit white noise (eq. 4.2),
``x_0 ~ N(mu0, Sigma0)``, payoff eq. 4.4 with weights ``Q_k, R_k, S_k``; the controller ``u`` may
also be asked to reach ``x_N ~ N(muN, SigmaN)`` (eq. 4.11). :func:`zero_order_hold` turns a
continuous model into the discrete one (eq. 4.70).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm


@dataclass(frozen=True)
class LQGame:
    """Per-step arrays of eq. 4.1/4.4: ``A`` (N, n, n), ``B`` (N, n, m), ``C`` (N, n, ℓ),
    ``D`` (N, n, r), ``Q`` (N, n, n), ``R`` (N, m, m), ``S`` (N, ℓ, ℓ); the initial Gaussian and the
    controller's optional terminal mean (a NaN entry leaves that component free) and covariance;
    ``dt`` the step (for time axes only)."""

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    S: np.ndarray
    mu0: np.ndarray
    Sigma0: np.ndarray
    muN: np.ndarray | None = None
    SigmaN: np.ndarray | None = None
    dt: float = 1.0

    @property
    def N(self) -> int:
        return self.A.shape[0]

    @property
    def n(self) -> int:
        return self.A.shape[1]

    @property
    def m(self) -> int:
        return self.B.shape[2]

    @property
    def ell(self) -> int:
        """The stopper's input size ℓ."""
        return self.C.shape[2]

    @property
    def r(self) -> int:
        return self.D.shape[2]


@dataclass(frozen=True)
class Strategies:
    """Both players' affine strategies ``u_k = ubar_k + K_k y_k``, ``v_k = vbar_k + L_k y_k``
    (Props. 7–8 with the feedback structure of eq. 4.51): ``U`` (N, m), ``V`` (N, ℓ),
    ``K`` (N, m, n), ``L`` (N, ℓ, n)."""

    U: np.ndarray
    V: np.ndarray
    K: np.ndarray
    L: np.ndarray


def zero_order_hold(
    A: np.ndarray, inputs: list[np.ndarray], dt: float
) -> tuple[np.ndarray, list[np.ndarray]]:
    """``exp(A dt)`` and ``∫_0^dt exp(A τ) dτ · G`` for each input matrix ``G`` (eq. 4.70).

    One matrix exponential of the augmented matrix ``[[A, G_1 … G_k], [0, 0]] dt``.
    """
    n = A.shape[0]
    widths = [g.shape[1] for g in inputs]
    aug = np.zeros((n + sum(widths), n + sum(widths)))
    aug[:n, :n] = A
    aug[:n, n:] = np.hstack(inputs)
    phi = expm(aug * dt)
    blocks = np.split(phi[:n, n:], np.cumsum(widths)[:-1], axis=1)
    return phi[:n, :n], blocks
