"""Gridded tables of a problem file (``tables:``) as functions of the expression language.

A :class:`Table` is a :class:`~gamespec.symbolic.grammar.FileFunction`: its name, among the symbols
of a walk, makes ``CL(mach, alpha)`` a call the grammar knows for that file, and each algebra
builds it its own way — floats and NumPy arrays through SciPy, CasADi through
``casadi.interpolant`` (whose derivatives, and for ``bspline`` the Hessian, come with it), Pyomo as
the same function in arithmetic and ``abs`` (:mod:`gamespec.symbolic.truncated`), SymPy as
an opaque function whose derivatives are functions of the language's checks but print nowhere (a
transform that differentiates a table is refused by the printer).

Three methods, the same numbers on every route (compared in ``tests/ocp/test_tables.py``):

- ``linear``: multilinear interpolation on the grid, extended linearly beyond its ends (CasADi's
  ``linear`` interpolant and SciPy's ``RegularGridInterpolator`` with ``fill_value=None``);
- ``bspline``: the tensor-product cubic spline interpolating the values with not-a-knot end
  conditions (CasADi's ``bspline`` interpolant; SciPy's ``make_interp_spline`` along each axis in
  turn, evaluated by ``NdBSpline``), each argument clamped to its axis' range: CasADi's B-spline is 0
  beyond its knots, so outside the grid the table holds its value at the nearest edge;
- ``akima`` (one axis only): Akima's (1970) piecewise cubic as SciPy's ``Akima1DInterpolator``
  computes it (its slopes at the grid points; Akima's own end conditions). CasADi has no Akima
  interpolant, so the same cubic is written as a B-spline of degree 3 with the interior grid points
  as double knots (a C1 piecewise cubic; its coefficients on each interval are the Hermite data
  ``y_i``, ``y_i + h m_i / 3``, ``y_(i+1) - h m_(i+1) / 3``, ``y_(i+1)``) and evaluated by
  ``casadi.Function.bspline``, which gives exact first and second derivatives; arguments clamped to
  the grid as for ``bspline``. Akima's slopes depend on the data nonlinearly, so there is no tensor
  product of Akima splines with fixed coefficients; a table of several axes is refused for
  ``akima`` (:func:`gamespec.specs.tables.checked_table`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import TYPE_CHECKING, Any, Literal

from gamespec.symbolic.grammar import FileFunction

if TYPE_CHECKING:
    import numpy as np

    from gamespec.symbolic.truncated import TruncatedTable

Method = Literal["linear", "bspline", "akima"]
MIN_POINTS: dict[str, int] = {"linear": 2, "bspline": 4, "akima": 3}
"""The fewest grid points per axis each method needs (a cubic not-a-knot spline: four; Akima's
slopes: three)."""


@dataclass(frozen=True, eq=False)
class Table(FileFunction):
    """The table ``name``: ``values`` (shape: one length per axis) on the strictly increasing
    ``axes``, interpolated by ``method``."""

    name: str
    axes: tuple[np.ndarray, ...]
    values: np.ndarray
    method: Method = "linear"

    @property
    def arity(self) -> int:
        return len(self.axes)

    def _clamped(self, args: list[Any], lower: Any, upper: Any) -> list[Any]:
        """The arguments clamped to the axes' ranges (``bspline``), unchanged (``linear``)."""
        if self.method == "linear":
            return args
        ranges = ((float(axis[0]), float(axis[-1])) for axis in self.axes)
        return [upper(lower(a, lo), hi) for a, (lo, hi) in zip(args, ranges, strict=True)]

    @cached_property
    def scipy(self) -> Any:
        """SciPy's interpolant of the table (``bspline``: the ``NdBSpline``, its knots ``t`` and
        coefficients ``c``), a function of an array of points, one row each."""
        import numpy as np
        from scipy.interpolate import NdBSpline, RegularGridInterpolator, make_interp_spline

        if self.method == "linear":
            return RegularGridInterpolator(self.axes, self.values, bounds_error=False, fill_value=None)
        if self.method == "akima":
            akima = self._akima
            return lambda points: akima(points[:, 0])
        coefficients, knots = self.values, []
        for axis, grid in enumerate(self.axes):
            spline = make_interp_spline(grid, coefficients, k=3, axis=axis)
            knots.append(spline.t)
            coefficients = np.moveaxis(spline.c, 0, axis)
        return NdBSpline(tuple(knots), coefficients, 3)

    @cached_property
    def _akima(self) -> Any:
        from scipy.interpolate import Akima1DInterpolator

        return Akima1DInterpolator(self.axes[0], self.values)

    def akima_bspline(self) -> tuple[list[float], list[float]]:
        """The knots and coefficients of the ``akima`` table as a cubic B-spline: the grid's ends
        four times, its interior points twice, and per interval the Hermite data of the Akima
        cubic (values and SciPy's Akima slopes)."""
        import numpy as np

        grid, values = self.axes[0], self.values
        slopes, widths = self._akima.derivative()(grid), np.diff(grid)
        coefficients = [values[0], values[0] + widths[0] * slopes[0] / 3]
        for i in range(1, grid.size - 1):
            coefficients += [values[i] - widths[i - 1] * slopes[i] / 3, values[i] + widths[i] * slopes[i] / 3]
        coefficients += [values[-1] - widths[-1] * slopes[-1] / 3, values[-1]]
        knots = np.concatenate([np.repeat(grid[:1], 4), np.repeat(grid[1:-1], 2), np.repeat(grid[-1:], 4)])
        return knots.tolist(), [float(c) for c in coefficients]

    def numpy(self, *args: Any) -> Any:
        """The table at NumPy arrays (broadcast together), an array of their shape."""
        import numpy as np

        arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in args))
        clamped = self._clamped(list(arrays), np.maximum, np.minimum)
        points = np.stack([np.ravel(a) for a in clamped], axis=-1)
        return np.asarray(self.scipy(points), dtype=float).reshape(arrays[0].shape)

    def floats(self, *args: float) -> float:
        if any(math.isnan(a) for a in args):
            raise ValueError(f"table {self.name} of NaN")
        return float(self.numpy(*args))

    @cached_property
    def _interpolant(self) -> Any:
        import casadi as ca
        import numpy as np

        if self.method == "akima":
            knots, coefficients = self.akima_bspline()
            spline = ca.Function.bspline(self.name, [knots], coefficients, [3], 1, {})
            x = ca.MX.sym("x")
            # an MX B-spline cannot be inlined into SX: kept as one call (SX graphs call it)
            return ca.Function(self.name, [x], [spline(x)], {"never_inline": True})
        grid = [list(map(float, axis)) for axis in self.axes]
        return ca.interpolant(self.name, self.method, grid, np.ravel(self.values, order="F").tolist())

    def casadi(self, *args: Any) -> Any:
        """The table at CasADi expressions (SX or MX): ``casadi.interpolant`` (``akima``: the
        B-spline of :meth:`akima_bspline`) of the clamped arguments."""
        import casadi as ca

        return self._interpolant(ca.vertcat(*self._clamped(list(args), ca.fmax, ca.fmin)))

    @cached_property
    def truncated(self) -> TruncatedTable:
        """The table in arithmetic and ``abs`` alone (:mod:`gamespec.symbolic.truncated`)."""
        from gamespec.symbolic.truncated import TruncatedTable

        return TruncatedTable.of(self)

    @cached_property
    def sympy(self) -> Any:
        """The table as a SymPy function class (:func:`sympy_function`)."""
        return sympy_function(self, ())


@lru_cache(maxsize=256)
def sympy_function(table: Table, derivative: tuple[int, ...]) -> Any:
    """A SymPy function class for ``table`` (``derivative`` empty) or for its partial derivative in
    the arguments ``derivative`` (indices, in the order taken): real-valued, differentiable, printed
    as the table's call only when it is the table itself."""

    def fdiff(self: Any, argindex: int = 1) -> Any:
        return sympy_function(table, (*derivative, argindex - 1))(*self.args)

    suffix = "".join(f"_d{i}" for i in derivative)
    attributes = {
        "nargs": table.arity,
        "table": table,
        "derivative": derivative,
        "fdiff": fdiff,
        "is_real": True,
        "__module__": __name__,
    }
    return type(f"{table.name}{suffix}", (TabulatedSympy.base(),), attributes)


class TabulatedSympy:
    """The SymPy base class of every table function (made at the first use: SymPy is imported only
    where it is needed)."""

    _base: Any = None

    @classmethod
    def base(cls) -> Any:
        if cls._base is None:
            import sympy as sp

            cls._base = type("TableFunction", (sp.Function,), {"__module__": __name__})
        return cls._base
