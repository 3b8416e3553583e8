"""Transcription grids for direct collocation, shared by every OCP backend so that the same
``method`` section gives the same discretization everywhere.

Time is normalized, ``t = t0 + tau * T``. States live at the *nodes* (interval starts, plus the
collocation points), the dynamics are imposed at *evaluation points*, and the defects read

    D @ X_nodes - T * W @ F(X_eval, U, t_eval) = 0,

with ``D`` (differentiation, in tau) and ``W`` (quadrature of the dynamics) sparse. Legendre–Gauss–
Radau of degree d: d points per interval, the last at the interval's end; controls at the
collocation points. Trapezoidal: controls at the nodes. The Lagrange term is ``T * q @ L(eval)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache, cached_property
from typing import TYPE_CHECKING

import numpy as np
from numpy.polynomial import legendre

if TYPE_CHECKING:
    import scipy.sparse as sps

Triplets = tuple[np.ndarray, np.ndarray, np.ndarray, tuple[int, int]]
"""A sparse matrix as ``(rows, cols, values, shape)``."""


@cache
def radau_points(degree: int) -> np.ndarray:
    """The ``degree`` Legendre–Gauss–Radau points on (0, 1], the last at 1 (flipped LGR roots;
    read-only, shared)."""
    if degree == 1:
        points = np.array([1.0])
    else:
        # Roots of P_{d-1}(x) + P_d(x) on [-1, 1) include -1; flipping puts the fixed point at +1.
        coeffs = np.zeros(degree + 1)
        coeffs[degree - 1] = 1.0
        coeffs[degree] = 1.0
        roots = np.sort(legendre.legroots(coeffs))
        points = np.sort((1.0 - roots[::-1]) / 2.0)
    points.flags.writeable = False
    return points


def lagrange_matrices(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For polynomial interpolation through ``nodes`` (on [0, 1]): the derivative of each basis
    polynomial at each node (``C[r, j] = l_r'(nodes[j])``) and the integrals of the basis over
    [0, 1] (quadrature weights)."""
    n = len(nodes)
    deriv = np.zeros((n, n))
    weights = np.zeros(n)
    for r in range(n):
        others = np.delete(nodes, r)
        basis = np.poly1d(np.poly(others) / np.prod(nodes[r] - others))
        deriv[r] = basis.deriv()(nodes)
        weights[r] = basis.integ()(1.0) - basis.integ()(0.0)
    return deriv, weights


@cache
def _radau_weights(degree: int) -> np.ndarray:
    return lagrange_matrices(radau_points(degree))[1]


@cache
def _radau_block(degree: int) -> np.ndarray:
    """``d × (d + 1)``: the derivative at each collocation point of the interpolant through the
    interval's start and its d collocation points (local time)."""
    return lagrange_matrices(np.concatenate([[0.0], radau_points(degree)]))[0][:, 1:].T


@dataclass(frozen=True)
class Grid:
    """A collocation grid on normalized time [0, 1]; Radau intervals of ``degree``, or of the
    per-interval ``degrees`` when given (from p-refinement)."""

    scheme: str
    intervals: int
    degree: int
    grading: float = 1.0
    mesh: tuple[float, ...] | None = None
    degrees: tuple[int, ...] | None = None

    @cached_property
    def interval_degrees(self) -> np.ndarray:
        """The number of collocation points of each interval (1 per interval, trapezoidal)."""
        if self.scheme != "radau":
            return np.ones(self.intervals, dtype=int)
        if self.degrees is not None:
            return np.asarray(self.degrees, dtype=int)
        return np.full(self.intervals, self.degree, dtype=int)

    @cached_property
    def breaks(self) -> np.ndarray:
        """Interval boundaries in tau: the given ``mesh`` (``intervals + 1`` points from 0 to 1, e.g.
        from mesh refinement), else geometric lengths when ``grading`` != 1, else uniform."""
        n = self.intervals
        if self.mesh is not None:
            return np.asarray(self.mesh, dtype=float)
        if self.grading == 1.0:
            return np.linspace(0.0, 1.0, n + 1)
        ratio = (1.0 / self.grading) ** (1.0 / max(n - 1, 1))
        lengths = ratio ** np.arange(n)
        return np.concatenate([[0.0], np.cumsum(lengths / lengths.sum())])

    @property
    def points_per_interval(self) -> int:
        """The points of every interval of a grid of one degree."""
        return self.degree if self.scheme == "radau" else 1

    def local_points(self, degree: int) -> np.ndarray:
        """The nodes of an interval of ``degree`` in local coordinates [0, 1], the start included."""
        if self.scheme == "radau":
            return np.concatenate([[0.0], radau_points(degree)])
        return np.array([0.0, 1.0])

    @cached_property
    def nodes(self) -> np.ndarray:
        """All state nodes in tau (``sum of the interval degrees + 1`` of them)."""
        h = np.diff(self.breaks)
        inner = [
            a + dh * self.local_points(int(d))[1:]
            for a, dh, d in zip(self.breaks[:-1], h, self.interval_degrees, strict=True)
        ]
        return np.concatenate([[0.0], *inner])

    @property
    def n_nodes(self) -> int:
        return int(self.interval_degrees.sum()) + 1

    @cached_property
    def eval_index(self) -> np.ndarray:
        """Indices of the nodes where the dynamics (and controls) are evaluated."""
        if self.scheme == "radau":
            return np.arange(1, self.n_nodes)
        return np.arange(self.n_nodes)

    @property
    def eval_tau(self) -> np.ndarray:
        return self.nodes[self.eval_index]

    @property
    def interval_start_index(self) -> np.ndarray:
        """Node index of each interval's start (the last entry is the final node)."""
        return np.concatenate([[0], np.cumsum(self.interval_degrees)])

    @cached_property
    def radau_weights(self) -> np.ndarray:
        """Per collocation point, the weight of its interval's d-point Radau quadrature on [0, 1]
        (interpolation through the collocation points alone; exact to degree 2d - 2, and 1 for
        d = 1, i.e. backward Euler)."""
        return np.concatenate([_radau_weights(int(d)) for d in self.interval_degrees])

    @cached_property
    def triplets(self) -> tuple[Triplets, Triplets, np.ndarray]:
        """``(D, W, q)`` with ``D`` and ``W`` as ``(rows, cols, values, shape)`` (what a backend's
        own sparse matrix is built from, without SciPy) and ``q`` the Lagrange quadrature weights."""
        h = np.diff(self.breaks)
        if self.scheme == "radau":
            degrees = self.interval_degrees
            rows, cols, vals = [], [], []
            for k, start in enumerate(self.interval_start_index[:-1]):
                d = int(degrees[k])
                block = _radau_block(d)
                for j in range(d):
                    for r in range(d + 1):
                        rows.append(start + j)
                        cols.append(start + r)
                        vals.append(block[j, r])
            n_points = self.n_nodes - 1
            diagonal = np.arange(n_points)
            scale = np.repeat(h, degrees)
            w_triplets = (diagonal, diagonal, scale, (n_points, n_points))
            q = scale * self.radau_weights
            return (np.array(rows), np.array(cols), np.array(vals), (n_points, self.n_nodes)), w_triplets, q
        k = np.arange(self.intervals)
        shape = (self.intervals, self.n_nodes)
        rows, cols = np.r_[k, k], np.r_[k, k + 1]
        d_triplets = (rows, cols, np.r_[-np.ones(self.intervals), np.ones(self.intervals)], shape)
        w_values = np.r_[h, h] / 2.0
        q = np.bincount(cols, weights=w_values, minlength=self.n_nodes)
        return d_triplets, (rows, cols, w_values, shape), q

    @cached_property
    def matrices(self) -> tuple[sps.csr_matrix, sps.csr_matrix, np.ndarray]:
        """``(D, W, q)``: defects ``D X - T W F`` and the Lagrange quadrature weights ``q``
        (:attr:`triplets` as SciPy sparse matrices)."""
        import scipy.sparse as sps

        d_triplets, w_triplets, q = self.triplets
        dmat, wmat = (
            sps.csr_matrix((vals, (rows, cols)), shape=shape)
            for rows, cols, vals, shape in (d_triplets, w_triplets)
        )
        return dmat, wmat, q

    def costate_scale(self) -> np.ndarray:
        """Per LGR defect row, the factor turning a defect multiplier into a costate estimate:
        ``lambda = -nu / w_j`` with w_j the Radau weight of the point, from the Lagrangian
        ``J + nu^T g`` with ``g = D X - T W F`` (defined for the Radau scheme only)."""
        return -1.0 / self.radau_weights
