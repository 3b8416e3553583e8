"""The safe expression language of problem files (DESIGN.md, "Expressions are data").

Strings are parsed with :mod:`ast` and walked against an explicit whitelist into SymPy: numbers,
declared names and ``t``, ``+ - * / **``, unary minus, the functions in :data:`FUNCTIONS` and the
constant ``pi``. Comparisons are accepted only by :func:`parse_relation`, for constraints. Nothing
is ever ``eval``-ed; anything else is an :class:`~gamespec.errors.ExpressionError` naming the
expression and the column.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import sympy as sp

from gamespec.errors import ExpressionError
from gamespec.limits import MAX_EXPRESSION_CHARS, MAX_EXPRESSION_NODES, MAX_MAGNITUDE

FUNCTIONS: dict[str, tuple[int, object]] = {
    "sin": (1, sp.sin),
    "cos": (1, sp.cos),
    "tan": (1, sp.tan),
    "asin": (1, sp.asin),
    "acos": (1, sp.acos),
    "atan": (1, sp.atan),
    "atan2": (2, sp.atan2),
    "exp": (1, sp.exp),
    "log": (1, sp.log),
    "sqrt": (1, sp.sqrt),
    "abs": (1, sp.Abs),
    "tanh": (1, sp.tanh),
    "min": (2, sp.Min),
    "max": (2, sp.Max),
    "sign": (1, sp.sign),
    "heaviside": (1, sp.Heaviside),
}
"""The whitelisted functions: name → (arity, SymPy function). ``sign(0) = 0`` and
``heaviside(0) = 1/2`` (SymPy's conventions), so that derivatives of ``abs``, ``min`` and ``max``
print and parse back (:mod:`gamespec.symbolic.printer`)."""
CONSTANTS: dict[str, sp.Expr] = {"pi": sp.pi}
RESERVED = frozenset(FUNCTIONS) | frozenset(CONSTANTS) | {"t"}
TIME = sp.Symbol("t", real=True)

MAX_NODES = MAX_EXPRESSION_NODES
"""Largest number of syntax-tree nodes in one expression."""

MAX_EXACT_EXPONENT = 1_024
"""Largest exponent magnitude for which a power of two exact numbers stays exact (``2**(1/3)``,
``pi**2``); larger ones are computed in floating point, not expanded."""

_FLOAT_FUNCTIONS: dict[type, Callable[..., float]] = {
    sp.sin: math.sin,
    sp.cos: math.cos,
    sp.tan: math.tan,
    sp.asin: math.asin,
    sp.acos: math.acos,
    sp.atan: math.atan,
    sp.atan2: math.atan2,
    sp.exp: math.exp,
    sp.log: math.log,
    sp.Abs: abs,
    sp.tanh: math.tanh,
    sp.Min: min,
    sp.Max: max,
    sp.sign: lambda x: float(_numpy().sign(x)),
    sp.Heaviside: lambda x, *h: float(_numpy().heaviside(x, 0.5)),
}


def _numpy() -> Any:
    """NumPy, imported when a constant's sign or unit step is first evaluated."""
    import numpy as np

    return np


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


_BINARY = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
}


def symbol(name: str) -> sp.Symbol:
    """The SymPy symbol gamespec uses for a declared name (real-valued)."""
    return TIME if name == "t" else sp.Symbol(name, real=True)


class _Translator:
    def __init__(self, text: str, symbols: Mapping[str, sp.Expr]) -> None:
        self.text = text
        self.symbols = symbols

    def fail(self, node: ast.AST, reason: str) -> ExpressionError:
        return ExpressionError(self.text, reason, getattr(node, "col_offset", None))

    def __call__(self, node: ast.AST) -> sp.Expr:
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, int | float):
                raise self.fail(node, f"only numbers are allowed as literals, not {node.value!r}")
            return sp.Float(node.value) if isinstance(node.value, float) else sp.Integer(node.value)
        if isinstance(node, ast.Name):
            if node.id in self.symbols:
                return self.symbols[node.id]
            if node.id in CONSTANTS:
                return CONSTANTS[node.id]
            if node.id in FUNCTIONS:
                raise self.fail(node, f"function {node.id!r} used without arguments")
            known = ", ".join(sorted(self.symbols)) or "none"
            raise self.fail(node, f"undefined symbol {node.id!r} (declared: {known})")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            return self.power(node)
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitXor):
            column = self.text.find("^", getattr(node.left, "end_col_offset", 0) or 0)
            raise ExpressionError(self.text, "'^' is not a power: use ** for powers", column)
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            return self.finite(node, _BINARY[type(node.op)](self(node.left), self(node.right)))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            value = self(node.operand)
            return -value if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.Call):
            return self.call(node)
        if isinstance(node, ast.Compare):
            raise self.fail(node, "comparisons are only allowed in constraints")
        raise self.fail(node, f"{type(node).__name__} is not allowed")

    def power(self, node: ast.BinOp) -> sp.Expr:
        """``a ** b``; a power of two numbers is first computed in floating point, so that towers
        such as ``9**9**9`` fail fast instead of being expanded exactly. Within range it is SymPy's
        own power (exact ``sqrt(2)``, ``2**(1/3)``, ``pi**2``; ``2.0**pi`` as SymPy keeps it), so
        that printed SymPy parses back to itself."""
        base, exponent = self(node.left), self(node.right)
        if base.is_number and exponent.is_number:
            try:
                value = float(base) ** float(exponent)
            except (OverflowError, ZeroDivisionError, TypeError):
                raise self.fail(node, "number out of range") from None
            if isinstance(value, complex):
                raise self.fail(node, "power of a negative number is not real")
            inexact = base.has(sp.Float) or exponent.has(sp.Float)
            if inexact or abs(float(exponent)) <= MAX_EXACT_EXPONENT:
                return self.finite(node, base**exponent)
            return self.finite(node, sp.Float(value) if value != int(value) else sp.Integer(int(value)))
        return self.finite(node, base**exponent)

    def finite(self, node: ast.AST, value: sp.Expr) -> sp.Expr:
        """Refuse results SymPy already knows to be infinite, undefined or complex (``1/0``), and
        numbers (the value, or the numeric terms and factors SymPy folded into it) that are out of
        range when computed in floating point (:func:`float_value`; ``exp(exp(exp(100)))``,
        ``x*1e300*1e300``). A constant that is not real there (``asin(2)``) parses, as SymPy keeps it;
        each kind's numeric evaluation refuses it where a real number is needed."""
        if value.has(sp.zoo, sp.oo, -sp.oo, sp.nan, sp.I):
            raise self.fail(node, "is infinite, undefined or not real")
        numbers = [value] if value.is_number else [a for a in value.args if a.is_number]
        for number in numbers:
            try:
                float_value(number)
            except OverflowError:
                raise self.fail(node, f"number out of range (beyond {MAX_MAGNITUDE:g})") from None
            except (ValueError, TypeError, RecursionError):
                pass  # not real (asin(2)): each kind refuses it where it evaluates the value
        return value

    def call(self, node: ast.Call) -> sp.Expr:
        if not isinstance(node.func, ast.Name):
            raise self.fail(node, "only calls of the whitelisted functions by name are allowed")
        if node.func.id not in FUNCTIONS:
            raise self.fail(node, f"unknown function {node.func.id!r}")
        if node.keywords:
            raise self.fail(node, "keyword arguments are not allowed")
        arity, func = FUNCTIONS[node.func.id]
        if len(node.args) != arity:
            raise self.fail(node, f"{node.func.id} takes {arity} argument(s), got {len(node.args)}")
        return self.finite(node, func(*(self(a) for a in node.args)))


def _parse_tree(text: str) -> ast.expr:
    if not isinstance(text, str):
        return ast.Constant(value=text)
    if len(text) > MAX_EXPRESSION_CHARS:
        raise ExpressionError(text[:40] + "...", f"expression longer than {MAX_EXPRESSION_CHARS} characters")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as err:
        col = (err.offset - 1) if err.offset else None
        raise ExpressionError(text, f"syntax error: {err.msg}", col) from None
    except (RecursionError, MemoryError, ValueError):
        raise ExpressionError(text[:40] + "...", "expression nested too deeply") from None
    if sum(1 for _ in ast.walk(tree)) > MAX_NODES:
        raise ExpressionError(text[:40] + "...", f"expression has more than {MAX_NODES} parts")
    return tree.body


def parse(text: str | float, symbols: Mapping[str, sp.Expr]) -> sp.Expr:
    """Parse an expression over ``symbols`` (name → SymPy expression) into SymPy (no comparisons)."""
    tree = _parse_tree(text)
    try:
        return _Translator(str(text), symbols)(tree)
    except RecursionError:
        raise ExpressionError(str(text)[:40] + "...", "expression nested too deeply") from None


@dataclass(frozen=True)
class Relation:
    """``lower <= expr <= upper`` (equality when both bounds are equal); bounds may be infinite."""

    expr: sp.Expr
    lower: float
    upper: float

    @property
    def is_equality(self) -> bool:
        return self.lower == self.upper


def parse_relation(text: str, symbols: Mapping[str, sp.Expr]) -> Relation:
    """Parse a constraint ``a <= b``, ``a >= b``, ``a == b`` or ``lo <= a <= hi`` into a Relation.

    A two-sided chain needs numeric (parameter-free) outer terms; one-sided relations become
    ``a - b`` compared with zero.
    """
    node = _parse_tree(text)
    tr = _Translator(text, symbols)
    if not isinstance(node, ast.Compare):
        raise ExpressionError(text, "a constraint needs one of <=, >=, ==")
    ops = [type(o) for o in node.ops]
    allowed = {ast.LtE, ast.GtE, ast.Eq, ast.Lt, ast.Gt}
    if not set(ops) <= allowed:
        raise tr.fail(node, "only <=, >=, == (and < >, read as <= >=) are allowed in constraints")
    terms = [tr(node.left), *(tr(c) for c in node.comparators)]
    inf = float("inf")
    if len(ops) == 1:
        diff = terms[0] - terms[1]
        op = ops[0]
        if op is ast.Eq:
            return Relation(diff, 0.0, 0.0)
        if op in (ast.LtE, ast.Lt):
            return Relation(diff, -inf, 0.0)
        return Relation(diff, 0.0, inf)
    if len(ops) == 2 and ops[0] == ops[1] and ops[0] is not ast.Eq:
        lo, mid, hi = terms
        if not (lo.is_number and hi.is_number):
            raise tr.fail(node, "the outer terms of a chained constraint must be numbers")
        lo_f, hi_f = float(lo), float(hi)
        if ops[0] in (ast.GtE, ast.Gt):
            lo_f, hi_f = hi_f, lo_f
        if lo_f > hi_f:
            raise tr.fail(node, f"empty range: {lo_f:g} > {hi_f:g}")
        return Relation(mid, lo_f, hi_f)
    raise tr.fail(node, "a constraint is one comparison or a chain lo <= expr <= hi")
