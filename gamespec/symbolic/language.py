"""The safe expression language of problem files in SymPy (DESIGN.md, "Expressions are data").

The whitelist walk is :mod:`gamespec.symbolic.grammar`'s; here it builds SymPy: numbers exact
(``Integer``, ``Float``), declared names as real symbols, the functions in :data:`FUNCTIONS`,
``pi``. Results SymPy knows to be infinite, undefined or not real, and numbers out of range, are an
:class:`~gamespec.errors.ExpressionError` naming the expression and the column.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping
from functools import lru_cache

import sympy as sp

from gamespec.errors import ExpressionError
from gamespec.limits import MAX_MAGNITUDE
from gamespec.symbolic.grammar import (
    BINARY,
    FLOAT_FUNCTIONS,
    FUNCTION_ARITY,
    RESERVED,
    FileFunction,
    Refused,
    Relation,
    expression,
    relation,
)

__all__ = [
    "CONSTANTS",
    "FUNCTIONS",
    "RESERVED",
    "TIME",
    "ExpressionError",
    "Relation",
    "float_value",
    "parse",
    "parse_relation",
    "symbol",
]

_SYMPY_FUNCTIONS: dict[str, object] = {
    "sin": sp.sin,
    "cos": sp.cos,
    "tan": sp.tan,
    "asin": sp.asin,
    "acos": sp.acos,
    "atan": sp.atan,
    "atan2": sp.atan2,
    "exp": sp.exp,
    "log": sp.log,
    "sqrt": sp.sqrt,
    "abs": sp.Abs,
    "tanh": sp.tanh,
    "min": sp.Min,
    "max": sp.Max,
    "sign": sp.sign,
    "heaviside": sp.Heaviside,
}
FUNCTIONS: dict[str, tuple[int, object]] = {n: (FUNCTION_ARITY[n], f) for n, f in _SYMPY_FUNCTIONS.items()}
"""The whitelisted functions: name → (arity, SymPy function). ``sign(0) = 0`` and
``heaviside(0) = 1/2`` (SymPy's conventions), so that derivatives of ``abs``, ``min`` and ``max``
print and parse back (:mod:`gamespec.symbolic.printer`)."""
CONSTANTS: dict[str, sp.Expr] = {"pi": sp.pi}
TIME = sp.Symbol("t", real=True)
MAX_EXACT_EXPONENT = 1_024
"""Largest exponent magnitude for which a power of two exact numbers stays exact (``2**(1/3)``,
``pi**2``); larger ones are computed in floating point, not expanded."""

_FLOAT_FUNCTIONS: dict[object, Callable[..., float]] = {
    _SYMPY_FUNCTIONS[name]: func
    for name, func in FLOAT_FUNCTIONS.items()
    if name not in ("sqrt", "heaviside")
} | {sp.Heaviside: lambda x, *_: FLOAT_FUNCTIONS["heaviside"](x)}
"""The SymPy function classes computed in floats (``sqrt`` is a SymPy power; ``Heaviside`` carries
its value at 0 as a second argument, always 1/2 here)."""


@lru_cache(maxsize=4096)
def float_value(expr: sp.Basic) -> float:
    """The value of a symbol-free expression computed in floating point, never by SymPy's exact
    evaluation (which for ``exp(exp(exp(100)))`` works at astronomic precision for ever).

    OverflowError when the value or an intermediate one exceeds
    :data:`~gamespec.limits.MAX_MAGNITUDE` in size, ValueError when one is not a real number,
    TypeError for an expression that is not a number (free symbols, unknown functions).
    """
    if expr.is_Number or expr.is_NumberSymbol:
        value = float(expr)
    elif expr.is_Add:
        value = math.fsum(float_value(a) for a in expr.args)
    elif expr.is_Mul:
        value = math.prod(float_value(a) for a in expr.args)
    elif expr.is_Pow:
        value = math.pow(float_value(expr.base), float_value(expr.exp))
    elif type(expr) in _FLOAT_FUNCTIONS:
        value = _FLOAT_FUNCTIONS[type(expr)](*(float_value(a) for a in expr.args))
    else:
        raise TypeError(f"{expr} is not a number")
    if math.isnan(value):
        raise ValueError(f"{expr} is not a real number")
    if not abs(value) <= MAX_MAGNITUDE:
        raise OverflowError(f"{expr} exceeds {MAX_MAGNITUDE:g} in size")
    return value


@lru_cache(maxsize=4096)
def symbol(name: str) -> sp.Symbol:
    """The SymPy symbol gamespec uses for a declared name (real-valued; kept per name: a symbol is
    immutable, and reports rebuild the same ones for every Result)."""
    return TIME if name == "t" else sp.Symbol(name, real=True)


class SympyAlgebra:
    """The grammar's walk building SymPy (exact numbers; :meth:`finite` on every result)."""

    def number(self, value: int | float) -> sp.Expr:
        """A literal, refused when it is not finite (``1e400`` reads as infinity)."""
        return self.finite(sp.Float(value) if isinstance(value, float) else sp.Integer(value))

    def constant(self, name: str) -> sp.Expr:
        return CONSTANTS[name]

    def binary(self, op: type[ast.operator], left: sp.Expr, right: sp.Expr) -> sp.Expr:
        """``left op right``; a quotient of zeros SymPy's floats divide as mpmath does (raising),
        refused as the floats' walk refuses it."""
        try:
            value = BINARY[op](left, right)
        except ZeroDivisionError:
            raise Refused("is infinite, undefined or not real") from None
        return self.finite(value)

    def negate(self, value: sp.Expr) -> sp.Expr:
        return -value

    def power(self, base: sp.Expr, exponent: sp.Expr) -> sp.Expr:
        """``a ** b``; a power of two numbers is first computed in floating point, so that towers
        such as ``9**9**9`` fail fast instead of being expanded exactly. Within range it is SymPy's
        own power (exact ``sqrt(2)``, ``2**(1/3)``, ``pi**2``; ``2.0**pi`` as SymPy keeps it), so
        that printed SymPy parses back to itself."""
        if base.is_number and exponent.is_number:
            try:
                value = float(base) ** float(exponent)
            except (OverflowError, ZeroDivisionError, TypeError):
                raise Refused("number out of range") from None
            if isinstance(value, complex):
                raise Refused("power of a negative number is not real")
            inexact = base.has(sp.Float) or exponent.has(sp.Float)
            if inexact or abs(float(exponent)) <= MAX_EXACT_EXPONENT:
                return self.finite(base**exponent)
            return self.finite(sp.Float(value) if value != int(value) else sp.Integer(int(value)))
        return self.finite(base**exponent)

    def call(self, name: str, args: list[sp.Expr]) -> sp.Expr:
        """``name(*args)``; of numbers, first computed in floating point, so that one out of range
        (``exp(1e+300)``, which SymPy's own evaluation of a Float fails on with a decimal error) is
        refused; one that is not real there (``asin(2)``) is kept as SymPy keeps it (see :meth:`finite`)."""
        if args and all(a.is_number for a in args):
            try:
                FLOAT_FUNCTIONS[name](*(float_value(a) for a in args))
            except OverflowError:
                raise Refused(f"number out of range (beyond {MAX_MAGNITUDE:g})") from None
            except (ValueError, TypeError, ZeroDivisionError, RecursionError):
                pass
        return self.finite(_SYMPY_FUNCTIONS[name](*args))

    def tabulated(self, function: FileFunction, args: list[sp.Expr]) -> sp.Expr:
        """A table (:mod:`gamespec.symbolic.tables`) of numbers computed in floats, as a backend
        computes it; of anything else its SymPy function."""
        if all(a.is_number for a in args):
            try:
                return sp.Float(function.floats(*(float_value(a) for a in args)))
            except (ValueError, TypeError, OverflowError):
                raise Refused("is infinite, undefined or not real") from None
        return function.sympy(*args)  # type: ignore[attr-defined, no-any-return]

    def scalar(self, value: sp.Expr) -> float | None:
        return float(value) if value.is_number else None

    @staticmethod
    def finite(value: sp.Expr) -> sp.Expr:
        """Refuse results SymPy already knows to be infinite, undefined or complex (``1/0``), and
        numbers (the value, or the numeric terms and factors SymPy folded into it) that are out of
        range when computed in floating point (:func:`float_value`; ``exp(exp(exp(100)))``,
        ``x*1e300*1e300``). A constant that is not real there (``asin(2)``) parses, as SymPy keeps it;
        each kind's numeric evaluation refuses it where a real number is needed."""
        if value.has(sp.zoo, sp.oo, -sp.oo, sp.nan, sp.I):
            raise Refused("is infinite, undefined or not real")
        numbers = [value] if value.is_number else [a for a in value.args if a.is_number]
        for number in numbers:
            try:
                float_value(number)
            except OverflowError:
                raise Refused(f"number out of range (beyond {MAX_MAGNITUDE:g})") from None
            except (ValueError, TypeError, RecursionError):
                pass  # not real (asin(2)): each kind refuses it where it evaluates the value
        return value


SYMPY = SympyAlgebra()


def parse(text: str | float, symbols: Mapping[str, sp.Expr]) -> sp.Expr:
    """Parse an expression over ``symbols`` (name → SymPy expression) into SymPy (no comparisons)."""
    return expression(text, symbols, SYMPY)


def parse_relation(text: str, symbols: Mapping[str, sp.Expr]) -> Relation:
    """Parse a constraint ``a <= b``, ``a >= b``, ``a == b`` or ``lo <= a <= hi`` into a Relation
    of SymPy expressions (:func:`gamespec.symbolic.grammar.relation`)."""
    return relation(text, symbols, SYMPY)
