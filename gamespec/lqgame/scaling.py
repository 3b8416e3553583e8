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
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import cholesky, solve_triangular


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


def _right_solve(root: np.ndarray, T: np.ndarray) -> np.ndarray:
    """``T R⁻¹``."""
    return solve_triangular(root, T.T, trans="T", lower=False).T
