"""The controller's problem of Algorithm 2 in whitened, normalized gains, so a conic solver sees data
of order one whatever the magnitudes of ``Q, R, S``, of the covariances and of the controller's
leverage on the terminal covariance.

The controller's payoff in its gains ``κ`` (section 4.4, eq. 4.56) is ``κᵀH κ + 2cᵀκ`` with
``H = H_KK ≻ 0``, subject to ``‖w + Tκ‖₂ ≤ 1`` (eq. 4.62, ``W`` already normalized by
``Σ_N^{-1/2}``). Two changes of variable make it well scaled:

- whitening, ``κ = R⁻¹ z`` with the Cholesky factor ``RᵀR = H``: a unit Hessian whatever ``H``'s
  scale (the missile endgame's ``H_KK`` has entries from 1e-31 to 27);
- normalization, ``z = s ζ`` with ``s = 1/‖T R⁻¹‖₂``, the whitened step that moves ``W`` by one in
  the spectral norm: the constraint map becomes ``T̂ = s T R⁻¹`` with ``‖T̂‖₂ = 1``, and the
  payoff, divided by ``s²``, ``‖ζ‖² + 2ĉᵀζ`` with ``ĉ = R⁻ᵀc / s``. Without it the controller of the
  missile endgame, whose gains move its terminal miss only weakly (``‖T R⁻¹‖₂ ≈ 0.1``), needs
  ``‖z‖`` of order 50, and Clarabel's interior point stalls.

The minimizer maps back exactly (``κ = s R⁻¹ ζ``), so the saddle point does not depend on the
scaling.

:class:`QPScaling` does the same for the controller's upper game in the mean inputs (eq. 4.43 subject
to eq. 4.42, ``min ½ŪᵀPŪ + qᵀŪ`` s.t. ``𝒢Ū = h``), and then equilibrates the result: each row of the
equality is divided by its norm (every component of ``μ_N`` is met to the same relative accuracy,
whatever its unit), and the variable by its magnitude ``ρ = max(‖ĥ‖, ‖ĉ‖)``, the size of the
constrained and of the unconstrained minimizer in whitened units, so ``Ū = ρ s R⁻¹ ξ`` with
``‖ξ‖`` of order one. Without it the missile endgame's QP has an optimal value near 9·10⁸ and
multipliers near 10⁷ (``R = 100``, a closing speed of 350 m/s to null in 0.7 s) and a KKT condition
number of 2.6·10⁷, so the terminal mean depends on how Clarabel's iterative refinement of its
regularized KKT solves ends (off by 6·10⁻⁸, 9.8·10⁻⁷ and 1.5·10⁻⁹ after one, two and three steps, at
the test's 10⁻⁶): on another machine's rounding, another answer. Scaled, the condition number is 74
and one step gives 7·10⁻¹³.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import cholesky, solve_triangular

from gamespec.lqgame.mean_steering import QPData


@dataclass(frozen=True)
class ControllerScaling:
    """``κ = s R⁻¹ ζ`` for the Hessian ``H = RᵀR`` (``R`` upper triangular) and the step ``s``."""

    root: np.ndarray
    step: float

    @classmethod
    def of(cls, hessian: np.ndarray, constraint_map: np.ndarray) -> ControllerScaling:
        """The scaling for the symmetric positive definite ``hessian`` and the map ``T`` of ``κ``
        into ``vec W`` (a map that vanishes leaves ``s = 1``)."""
        root = cholesky((hessian + hessian.T) / 2, lower=False)
        size = float(np.linalg.norm(_right_solve(root, constraint_map), 2))
        return cls(root, 1.0 / size if size > 0 else 1.0)

    def linear_term(self, linear: np.ndarray) -> np.ndarray:
        """``ĉ = R⁻ᵀc / s``."""
        return solve_triangular(self.root, linear, trans="T", lower=False) / self.step

    def map(self, T: np.ndarray) -> np.ndarray:
        """``T̂ = s T R⁻¹``."""
        return self.step * _right_solve(self.root, T)

    def unscale(self, zeta: np.ndarray) -> np.ndarray:
        """``κ = s R⁻¹ ζ``."""
        return self.step * solve_triangular(self.root, zeta, lower=False)


@dataclass(frozen=True)
class QPScaling:
    """``Ū = ρ s R⁻¹ ξ`` for the QP ``min ½ŪᵀPŪ + qᵀŪ`` s.t. ``AŪ = b`` (:class:`QPData`), with
    ``RᵀR = P/2`` and ``s`` of :class:`ControllerScaling`, the rows of ``s A R⁻¹`` divided by their
    norms ``d`` and the magnitude ``ρ``: the scaled QP is ``min ½ξᵀ(2I)ξ + q̂ᵀξ`` s.t.
    ``D⁻¹ s A R⁻¹ ξ = D⁻¹ b / ρ``, whose value is the original's divided by ``(ρ s)²``."""

    whitening: ControllerScaling
    rows: np.ndarray
    magnitude: float

    @classmethod
    def of(cls, qp: QPData) -> QPScaling:
        """The scaling of ``qp`` (``P`` symmetric positive definite)."""
        size = qp.q.size
        A = np.zeros((0, size)) if qp.A is None else qp.A
        b = np.zeros(0) if qp.b is None else qp.b
        whitening = ControllerScaling.of(qp.P / 2, A)
        norms = np.linalg.norm(whitening.map(A), axis=1)
        rows = np.where(norms > 0, norms, 1.0)
        magnitude = max(
            float(np.linalg.norm(b / rows)), float(np.linalg.norm(whitening.linear_term(qp.q / 2)))
        )
        return cls(whitening, rows, magnitude if magnitude > 0 else 1.0)

    def scaled(self, qp: QPData) -> QPData:
        """The scaled QP in ``ξ``."""
        q = 2 * self.whitening.linear_term(qp.q / 2) / self.magnitude
        P = 2 * np.eye(q.size)
        if qp.A is None or qp.b is None:
            return QPData(P=P, q=q)
        A = self.whitening.map(qp.A) / self.rows[:, None]
        return QPData(P=P, q=q, A=A, b=qp.b / self.rows / self.magnitude)

    def unscale(self, xi: np.ndarray) -> np.ndarray:
        """``Ū = ρ s R⁻¹ ξ``."""
        return self.magnitude * self.whitening.unscale(xi)


def _right_solve(root: np.ndarray, T: np.ndarray) -> np.ndarray:
    """``T R⁻¹``."""
    return solve_triangular(root, T.T, trans="T", lower=False).T
