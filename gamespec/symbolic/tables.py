"""Gridded tables of a problem file (``tables:``) as functions of the expression language.

A :class:`Table` is a :class:`~gamespec.symbolic.grammar.FileFunction`: its name, among the symbols
of a walk, makes ``CL(mach, alpha)`` a call the grammar knows for that file, and each algebra
builds it its own way — floats and NumPy arrays through SciPy, CasADi through
``casadi.interpolant`` (whose derivatives, and for ``bspline`` the Hessian, come with it), SymPy as
an opaque function whose derivatives are functions of the language's checks but print nowhere (a
transform that differentiates a table is refused by the printer).

Two methods, the same numbers on every route (compared in ``tests/ocp/test_tables.py``):

- ``linear``: multilinear interpolation on the grid, extended linearly beyond its ends (CasADi's
  ``linear`` interpolant and SciPy's ``RegularGridInterpolator`` with ``fill_value=None``);
- ``bspline``: the tensor-product cubic spline interpolating the values with not-a-knot end
  conditions (CasADi's ``bspline`` interpolant; SciPy's ``make_interp_spline`` along each axis in
  turn, evaluated by ``NdBSpline``), each argument clamped to its axis' range: CasADi's B-spline is 0
  beyond its knots, so outside the grid the table holds its value at the nearest edge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from typing import TYPE_CHECKING, Any, Literal

from gamespec.symbolic.grammar import FileFunction

if TYPE_CHECKING:
    import numpy as np

Method = Literal["linear", "bspline"]
MIN_POINTS: dict[str, int] = {"linear": 2, "bspline": 4}
"""The fewest grid points per axis each method needs (a cubic not-a-knot spline: four)."""


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
    def _scipy(self) -> Any:
        import numpy as np
        from scipy.interpolate import NdBSpline, RegularGridInterpolator, make_interp_spline

        if self.method == "linear":
            return RegularGridInterpolator(self.axes, self.values, bounds_error=False, fill_value=None)
        coefficients, knots = self.values, []
        for axis, grid in enumerate(self.axes):
            spline = make_interp_spline(grid, coefficients, k=3, axis=axis)
            knots.append(spline.t)
            coefficients = np.moveaxis(spline.c, 0, axis)
        return NdBSpline(tuple(knots), coefficients, 3)

    def numpy(self, *args: Any) -> Any:
        """The table at NumPy arrays (broadcast together), an array of their shape."""
        import numpy as np

        arrays = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in args))
        clamped = self._clamped(list(arrays), np.maximum, np.minimum)
        points = np.stack([np.ravel(a) for a in clamped], axis=-1)
        return np.asarray(self._scipy(points), dtype=float).reshape(arrays[0].shape)

    def floats(self, *args: float) -> float:
        if any(math.isnan(a) for a in args):
            raise ValueError(f"table {self.name} of NaN")
        return float(self.numpy(*args))

    @cached_property
    def _interpolant(self) -> Any:
        import casadi as ca
        import numpy as np

        grid = [list(map(float, axis)) for axis in self.axes]
        return ca.interpolant(self.name, self.method, grid, np.ravel(self.values, order="F").tolist())

    def casadi(self, *args: Any) -> Any:
        """The table at CasADi expressions (SX or MX): ``casadi.interpolant`` of the clamped
        arguments."""
        import casadi as ca

        return self._interpolant(ca.vertcat(*self._clamped(list(args), ca.fmax, ca.fmin)))

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
