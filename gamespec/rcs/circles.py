"""Circular path constraints read from their SymPy form, so that figures can draw them as disks.

A path constraint ``(x − a)² + (y − b)² ≥ r²`` (in any arrangement: ``x**2 + y**2 - 2*a*x ... >= c``,
parameters allowed) over a planar pair ``(x, y)`` is, once the parameters have values, a polynomial
``k (x² + y²) + p x + q y + c`` compared with zero. It is a circle when it has degree two in ``x``
and ``y`` with equal square coefficients, no ``xy`` term and nothing else: centre ``(−p, −q)/2k``,
``r² = |centre|² − c/k``. The side the constraint allows decides whether the disk is an obstacle
(keep out) or the region the path must stay in (keep in).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass

import sympy as sp

from gamespec.errors import ExpressionError
from gamespec.symbolic.language import parse_relation, symbol


@dataclass(frozen=True)
class Circle:
    """A circle of a path constraint: ``keep_out`` when the path must stay outside it."""

    center: tuple[float, float]
    radius: float
    keep_out: bool
    text: str


def circle_of(
    text: str, pair: tuple[str, str], names: Iterable[str], parameters: Mapping[str, float]
) -> Circle | None:
    """The circle that the one-sided constraint ``text`` bounds in the plane of ``pair``, or None
    when it is no circle over that pair (other variables, a chained range, an ellipse, ...)."""
    symbols = {n: symbol(n) for n in {*names, *parameters, *pair, "t"}}
    try:
        relation = parse_relation(text, symbols)
    except ExpressionError:
        return None
    if relation.is_equality or (relation.lower != 0 and relation.upper != 0):
        return None
    x, y = symbol(pair[0]), symbol(pair[1])
    expr = sp.expand(relation.expr.subs({symbol(k): v for k, v in parameters.items()}))
    if not expr.free_symbols <= {x, y}:
        return None
    try:
        poly = sp.Poly(expr, x, y)
    except sp.PolynomialError:
        return None
    coeff = {m: float(c) for m, c in poly.terms()}
    k = coeff.get((2, 0), 0.0)
    if (
        poly.total_degree() != 2
        or k == 0
        or coeff.get((0, 2)) != k
        or set(coeff) - {(2, 0), (0, 2), (1, 0), (0, 1), (0, 0)}
    ):
        return None
    cx, cy = -coeff.get((1, 0), 0.0) / (2 * k), -coeff.get((0, 1), 0.0) / (2 * k)
    r2 = cx**2 + cy**2 - coeff.get((0, 0), 0.0) / k
    if r2 <= 0:
        return None
    outside_allowed = (relation.lower == 0) == (k > 0)
    return Circle((cx, cy), float(r2**0.5), keep_out=outside_allowed, text=text)


def circles(
    constraints: Iterable[str], pair: tuple[str, str], names: Iterable[str], parameters: Mapping[str, float]
) -> list[Circle]:
    """The circles among ``constraints`` over the planar ``pair`` (see :func:`circle_of`)."""
    names = list(names)
    found = (circle_of(c, pair, names, parameters) for c in constraints)
    return [c for c in found if c is not None]
