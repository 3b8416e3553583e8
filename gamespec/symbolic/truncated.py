"""A table (:class:`~gamespec.symbolic.tables.Table`) as an expression of arithmetic and ``abs``
alone, for a target with neither interpolants nor conditionals that it differentiates exactly
(Pyomo's NL files: ripopt differentiates ``Expr_if`` wrongly).

Every method is a tensor product of B-splines on each axis with SciPy's knots and coefficients:
``linear`` the hats of the grid (degree 1, the grid's ends doubled) with the table's values as
coefficients, ``bspline`` the not-a-knot cubic of ``make_interp_spline``, ``akima`` the cubic
B-spline of :meth:`~gamespec.symbolic.tables.Table.akima_bspline` (interior knots doubled). One
basis function ``B`` on its knots ``t_i < ... < t_e`` (distinct), in the coordinate
``s = (c - t_i) / (t_e - t_i)`` of its argument ``c``, is exactly

    ``p(s) + sum_b sum_j D[b, j] (s - s_b)_+ ** j``,  ``(z)_+ = (z + |z|) / 2``,

with ``p`` its first piece and ``D[b, j]`` the jump of its ``j``-th derivative at the knot ``s_b``
over ``j!`` (Boor, *A Practical Guide to Splines*, 2001, ch. IX, the truncated power basis), ``j``
from the order its knot's multiplicity ``mu`` lets jump (``k + 1 - mu``) to the degree ``k``: a
simple cubic knot contributes ``(z)_+ ** 3`` only, C2 as the spline, and ``(z)_+ ** j`` with
``j >= 2`` has exact first and second derivatives at its own knot whatever ``|z|``'s derivative at
0 is taken to be. The argument is clamped (``max``/``min`` through ``abs``) to the basis function's
support on each side where the function is flat there (so that no truncated power grows beyond it
and the sum stays local, its cancellation the size of a few coefficients), and at the grid's ends
for ``bspline`` and ``akima`` (which hold their edge value); ``linear`` extends its end pieces, as
SciPy's ``RegularGridInterpolator`` with ``fill_value=None``. The table is then
``sum_a C[a] prod_axis B_(a_axis)(x_axis)``, nested one sum per axis.

Rounding is measured, not assumed: :meth:`TruncatedTable.error` compares the form, in NumPy, with
:meth:`Table.numpy` at the grid's points, its midpoints and random points inside and beyond it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np

    from gamespec.symbolic.tables import Table

SAMPLES = 512
"""Random points of :meth:`TruncatedTable.error` (besides the grid and its midpoints)."""


def _positive(z: Any) -> Any:
    """``max(z, 0)`` as ``(z + |z|) / 2``."""
    return 0.5 * (z + abs(z))


def _lower(x: Any, bound: float) -> Any:
    """``max(x, bound)`` through ``abs``."""
    return 0.5 * (x + bound + abs(x - bound))


def _upper(x: Any, bound: float) -> Any:
    """``min(x, bound)`` through ``abs``."""
    return 0.5 * (x + bound - abs(x - bound))


def _power(z: Any, j: int) -> Any:
    """``z ** j`` as a product (a polynomial for any target, derivatives exact at 0)."""
    value = z
    for _ in range(j - 1):
        value = value * z
    return value


@dataclass(frozen=True)
class Basis:
    """One B-spline of one axis in truncated powers: its argument clamped to ``[lower, upper]``
    (infinite: not clamped), ``s = (c - origin) / width``, the first piece's coefficients ``first``
    (of ``s ** 0 ... s ** k``; empty when the function is zero left of ``origin``) and per knot
    ``(s_b, j0, (D[b, j0], ..., D[b, k]))``."""

    lower: float
    upper: float
    origin: float
    width: float
    first: tuple[float, ...]
    knots: tuple[tuple[float, int, tuple[float, ...]], ...]

    def __call__(self, x: Any) -> Any:
        """The basis function at ``x`` (a number, a NumPy array or a target's expression)."""
        if math.isfinite(self.lower):
            x = _lower(x, self.lower)
        if math.isfinite(self.upper):
            x = _upper(x, self.upper)
        s = (x - self.origin) * (1.0 / self.width)
        value: Any = 0.0
        for coefficient in reversed(self.first):
            value = value * s + coefficient
        for at, j0, jumps in self.knots:
            z = _positive(s - at) if at else _positive(s)
            for j, jump in enumerate(jumps, start=j0):
                value = value + jump * _power(z, j)
        return value


def axis_basis(knots: np.ndarray, k: int, clamped: bool) -> list[Basis]:
    """The B-splines of degree ``k`` on the knot vector ``knots`` (the grid's ends ``k + 1`` times)
    in truncated powers, clamped to the grid (``clamped``) or extended by their end pieces."""
    import numpy as np
    from scipy.interpolate import BSpline

    lo, hi = float(knots[0]), float(knots[-1])
    bases = []
    for i in range(knots.size - k - 1):
        local = knots[i : i + k + 2]
        origin, width = float(local[0]), float(local[-1] - local[0])
        normalized = (local - origin) / width
        spline = BSpline.basis_element(normalized, extrapolate=False)
        at, mult = np.unique(normalized, return_counts=True)
        right = [_taylor(spline, float(a), k) for a in at[:-1]]
        first: tuple[float, ...] = ()
        pieces = []
        if origin == lo:
            first = tuple(float(v) for v in right[0])
        else:
            j0 = k + 1 - int(mult[0])
            pieces.append((0.0, j0, tuple(float(v) for v in right[0][j0:])))
        for b in range(1, len(right)):
            left = _shift(right[b - 1], float(at[b] - at[b - 1]))
            j0 = k + 1 - int(mult[b])
            pieces.append((float(at[b]), j0, tuple(float(v) for v in (right[b] - left)[j0:])))
        lower = lo if (clamped and origin == lo) else -math.inf
        upper = math.inf if (not clamped and float(local[-1]) == hi) else float(local[-1])
        bases.append(Basis(lower, upper, origin, width, first, tuple(pieces)))
    return bases


def _taylor(spline: Any, at: float, k: int) -> np.ndarray:
    """``spline``'s Taylor coefficients at ``at`` from the right (SciPy evaluates a knot in the
    interval it starts)."""
    import numpy as np

    return np.array([float(spline(at, nu=j)) / math.factorial(j) for j in range(k + 1)])


def _shift(coefficients: np.ndarray, delta: float) -> np.ndarray:
    """The Taylor coefficients of the same polynomial about a point ``delta`` further on."""
    import numpy as np

    k = coefficients.size - 1
    return np.array(
        [
            sum(coefficients[m] * math.comb(m, j) * delta ** (m - j) for m in range(j, k + 1))
            for j in range(k + 1)
        ]
    )


@dataclass(frozen=True)
class TruncatedTable:
    """A table as ``sum_a coefficients[a] prod_axis axes[axis][a_axis](x_axis)``."""

    axes: tuple[tuple[Basis, ...], ...]
    coefficients: np.ndarray

    @classmethod
    def of(cls, table: Table) -> TruncatedTable:
        """The form of ``table`` (its method's B-splines and coefficients, SciPy's)."""
        import numpy as np

        clamped = table.method != "linear"
        if table.method == "linear":
            knots = [np.concatenate([a[:1], a, a[-1:]]) for a in table.axes]
            coefficients, k = np.asarray(table.values, dtype=float), 1
        elif table.method == "akima":
            t, c = table.akima_bspline()
            knots, coefficients, k = [np.asarray(t)], np.asarray(c), 3
        else:
            spline = table.scipy
            knots, coefficients, k = [np.asarray(t) for t in spline.t], np.asarray(spline.c), 3
        return cls(tuple(tuple(axis_basis(t, k, clamped)) for t in knots), coefficients)

    def __call__(self, *args: Any) -> Any:
        """The table at ``args`` (numbers, NumPy arrays broadcast together, or a target's
        expressions with ``+``, ``*`` and ``abs``)."""
        values = [[basis(arg) for basis in bases] for bases, arg in zip(self.axes, args, strict=True)]
        return _contract(self.coefficients, values)

    def error(self, table: Table) -> float:
        """The largest difference from :meth:`Table.numpy` at the grid's points and midpoints (at
        most :data:`SAMPLES` of them) and :data:`SAMPLES` random points of the grid's box widened by
        half its size each way, relative to the larger of the values' range and the largest value
        there (``linear`` grows beyond the grid; a constant table has no range)."""
        import numpy as np

        rng = np.random.default_rng(0)
        lows = np.array([a[0] for a in table.axes])
        highs = np.array([a[-1] for a in table.axes])
        spans = highs - lows
        dense = [np.sort(np.concatenate([a, 0.5 * (a[1:] + a[:-1])])) for a in table.axes]
        grid = np.stack([g.ravel() for g in np.meshgrid(*dense, indexing="ij")], axis=-1)
        grid = grid[rng.permutation(len(grid))[:SAMPLES]]
        random = rng.uniform(lows - spans / 2, highs + spans / 2, size=(SAMPLES, len(table.axes)))
        points = np.concatenate([grid, random])
        expected = table.numpy(*points.T)
        scale = max(float(np.ptp(table.values)), float(np.max(np.abs(expected))), math.ulp(0.0))
        return float(np.max(np.abs(self(*points.T) - expected))) / scale


def _contract(coefficients: np.ndarray, values: Sequence[Sequence[Any]]) -> Any:
    """``sum_i values[0][i] * (the rest contracted with coefficients[i])``, each axis' basis
    functions evaluated once (``values``), the last axis a plain sum (zero coefficients left out)."""
    first, rest = values[0], values[1:]
    total: Any = 0.0
    for i, value in enumerate(first):
        inner = coefficients[i]
        if not rest:
            if inner != 0.0:
                total = total + float(inner) * value
            continue
        if inner.any():
            total = total + value * _contract(inner, rest)
    return total
