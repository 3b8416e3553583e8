"""The flow field of eq. 5.3: drift ``f(x)`` and diffusion ``g(x)`` as SymPy expressions of the
position, evaluated vectorized by :func:`gamespec.symbolic.calculus.numeric_function`, with the
Jacobian ``∂f/∂x`` (eq. 5.6) from :func:`gamespec.symbolic.calculus.jacobian`."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import sympy as sp

from gamespec.symbolic.calculus import jacobian, numeric_function


def _evaluate(exprs: sp.Matrix, names: tuple[sp.Symbol, sp.Symbol], points: np.ndarray) -> np.ndarray:
    """Each entry of ``exprs`` at ``points`` (..., 2): an array (..., *exprs.shape)."""
    points = np.asarray(points, dtype=float)
    values = numeric_function(list(exprs), names)(points[..., 0], points[..., 1])
    return np.moveaxis(values, 0, -1).reshape(points.shape[:-1] + exprs.shape)


@dataclass(frozen=True)
class FlowField:
    """``dx = (u + f(x)) dt + g(x) dw`` (eq. 5.1, 5.3) for one agent; ``position`` are the two
    symbols of ``x``; ``drift`` is 2 × 1 and ``diffusion`` 2 × 2, both free of other symbols."""

    position: tuple[sp.Symbol, sp.Symbol]
    drift_exprs: sp.Matrix
    diffusion_exprs: sp.Matrix

    @cached_property
    def jacobian_exprs(self) -> sp.Matrix:
        """``∂f/∂x`` (eq. 5.6), symbolically."""
        return jacobian(self.drift_exprs, self.position)

    @cached_property
    def constant_diffusion(self) -> bool:
        """True when ``g`` does not depend on the position."""
        return not self.diffusion_exprs.free_symbols

    def drift(self, points: np.ndarray) -> np.ndarray:
        """``f(x)`` at ``points`` (..., 2) → (..., 2)."""
        return _evaluate(self.drift_exprs, self.position, points)[..., 0]

    def jacobian(self, points: np.ndarray) -> np.ndarray:
        """``∂f/∂x`` at ``points`` (..., 2) → (..., 2, 2)."""
        return _evaluate(self.jacobian_exprs, self.position, points)

    def diffusion(self, points: np.ndarray) -> np.ndarray:
        """``g(x)`` at ``points`` (..., 2) → (..., 2, 2)."""
        return _evaluate(self.diffusion_exprs, self.position, points)
