"""The controller's problem of Algorithm 2 in whitened gains, so a conic solver sees data of order
one whatever the magnitudes of ``Q, R, S`` and of the covariances.

The controller's payoff in its gains ``κ`` (section 4.4, eq. 4.56) is ``κᵀH κ + 2cᵀκ`` with
``H = H_KK ≻ 0``. With the Cholesky factor ``RᵀR = H`` and ``κ = R⁻¹ z`` it is ``‖z‖² + 2ĉᵀz``,
``ĉ = R⁻ᵀc``: a unit Hessian, whatever ``H``'s scale; the affine map ``w + T κ`` of the terminal
factor ``W`` (eq. 4.62, already normalized by ``Σ_N^{-1/2}``) becomes ``w + (T R⁻¹) z``. The
minimizer maps back exactly, so the saddle point does not depend on the scaling.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import cholesky, solve_triangular


@dataclass(frozen=True)
class Whitening:
    """``κ = R⁻¹ z`` for the Hessian ``H = RᵀR`` (``R`` upper triangular)."""

    root: np.ndarray

    @classmethod
    def of(cls, hessian: np.ndarray) -> Whitening:
        """The whitening of the symmetric positive definite ``hessian``."""
        return cls(cholesky((hessian + hessian.T) / 2, lower=False))

    def linear_term(self, linear: np.ndarray) -> np.ndarray:
        """``ĉ = R⁻ᵀc``."""
        return solve_triangular(self.root, linear, trans="T", lower=False)

    def map(self, T: np.ndarray) -> np.ndarray:
        """``T R⁻¹``."""
        return solve_triangular(self.root, T.T, trans="T", lower=False).T

    def unscale(self, z: np.ndarray) -> np.ndarray:
        """``κ = R⁻¹ z``."""
        return solve_triangular(self.root, z, lower=False)
