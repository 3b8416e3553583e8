"""The whitelist of the expression language of problem files, without a computer-algebra system
(DESIGN.md, "Expressions are data").

A string is parsed with :mod:`ast` and walked against an explicit whitelist: numbers, declared
names and ``t``, ``+ - * / **``, unary minus, the functions in :data:`FUNCTION_ARITY` and the
constant ``pi``; comparisons only in :func:`relation`, for constraints. Nothing is ever
``eval``-ed; anything else is an :class:`~gamespec.errors.ExpressionError` naming the expression
and the column.

The walk builds its value in an :class:`Algebra`: SymPy (:mod:`gamespec.symbolic.language`, the
form the transforms differentiate), floats (:data:`FLOATS`, the checks at load and the values of
bounds and parameters), the names it depends on (:data:`NAMES`) or a backend's own expressions
(:class:`gamespec.symbolic.library.LibraryAlgebra`, a CasADi graph built straight from the file),
so that one walker decides what an expression may be.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Protocol

from gamespec.errors import ExpressionError
from gamespec.limits import MAX_EXPRESSION_CHARS, MAX_EXPRESSION_NODES, MAX_MAGNITUDE

FUNCTION_ARITY: dict[str, int] = {
    "sin": 1,
    "cos": 1,
    "tan": 1,
    "asin": 1,
    "acos": 1,
    "atan": 1,
    "atan2": 2,
    "exp": 1,
    "log": 1,
    "sqrt": 1,
    "abs": 1,
    "tanh": 1,
    "min": 2,
    "max": 2,
    "sign": 1,
    "heaviside": 1,
}
"""The whitelisted functions and their arities. ``sign(0) = 0`` and ``heaviside(0) = 1/2``."""
CONSTANT_NAMES = frozenset({"pi"})
RESERVED = frozenset(FUNCTION_ARITY) | CONSTANT_NAMES | {"t"}

BINARY: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
}
"""The binary operators other than ``**``, by their syntax-tree node."""


class Refused(ValueError):
    """Raised by an :class:`Algebra` for a value it will not build; the walker names the column."""


class Algebra(Protocol):
    """Where a walk builds its value: what a number, ``pi``, an operator and a function become."""

    def number(self, value: int | float) -> Any: ...

    def constant(self, name: str) -> Any: ...

    def binary(self, op: type[ast.operator], left: Any, right: Any) -> Any: ...

    def negate(self, value: Any) -> Any: ...

    def power(self, base: Any, exponent: Any) -> Any: ...

    def call(self, name: str, args: list[Any]) -> Any: ...

    def scalar(self, value: Any) -> float | None:
        """``value`` as a float when it is a number (no symbols), else None."""


def _checked(value: float) -> float:
    """``value`` when it is a real number within :data:`~gamespec.limits.MAX_MAGNITUDE`."""
    if math.isnan(value):
        raise Refused("is infinite, undefined or not real")
    if not abs(value) <= MAX_MAGNITUDE:
        raise Refused(f"number out of range (beyond {MAX_MAGNITUDE:g})")
    return value


def _unit_step(x: float) -> float:
    return 0.5 if x == 0 else float(x > 0)


FLOAT_FUNCTIONS: dict[str, Callable[..., float]] = {
    "sin": math.sin,
    "cos": math.cos,
    "tan": math.tan,
    "asin": math.asin,
    "acos": math.acos,
    "atan": math.atan,
    "atan2": math.atan2,
    "exp": math.exp,
    "log": math.log,
    "sqrt": math.sqrt,
    "abs": abs,
    "tanh": math.tanh,
    "min": min,
    "max": max,
    "sign": lambda x: float((x > 0) - (x < 0)),
    "heaviside": _unit_step,
}
"""The whitelisted functions on floats (``math``; ``sign`` and ``heaviside`` as in SymPy)."""


@dataclass(frozen=True)
class Unknown:
    """A value that depends on a name without a number. ``scale`` bounds the numeric coefficient
    SymPy would fold into it (``x*1e300*1e300`` is ``1e600*x``; terms add their scales), so that
    a check without SymPy refuses what parsing into SymPy refuses as out of range."""

    scale: float = 1.0


UNKNOWN = Unknown()


def _scale(value: float | Unknown) -> float:
    return value.scale if isinstance(value, Unknown) else abs(value)


def _unknown_result(func: Callable[..., Any], args: tuple[float | Unknown, ...]) -> Unknown:
    """The :class:`Unknown` that ``func`` of ``args`` (one of them unknown) gives."""
    scales = [_scale(a) for a in args]
    if func is operator.add or func is operator.sub:
        scale = scales[0] + scales[1]
    elif func is operator.mul:
        scale = scales[0] * scales[1]
    elif func is operator.truediv:
        if scales[1] == 0:
            raise Refused("is infinite, undefined or not real")
        scale = scales[0] / scales[1]
    elif func is operator.pow and not isinstance(args[1], Unknown):
        if scales[0] == 0 and args[1] < 0:
            raise Refused("is infinite, undefined or not real")
        try:
            scale = scales[0] ** args[1]
        except OverflowError:
            raise Refused(f"number out of range (beyond {MAX_MAGNITUDE:g})") from None
    else:
        scale = 1.0
    return Unknown(_checked(scale))


class FloatAlgebra:
    """Floats, with an :class:`Unknown` for a value that depends on a name without a number: a
    walk over ``{name: UNKNOWN}`` checks an expression without computing it (the checks at load),
    one over ``{name: float}`` computes it (bounds, derived parameters). A number that is
    infinite, not real or beyond :data:`~gamespec.limits.MAX_MAGNITUDE` (``1/0``, ``log(0)``,
    ``sqrt(-1)``, ``exp(1000)``, ``x*1e300*1e300``) is refused."""

    def number(self, value: int | float) -> float:
        try:
            return _checked(float(value))
        except OverflowError:
            raise Refused(f"number out of range (beyond {MAX_MAGNITUDE:g})") from None

    def constant(self, name: str) -> float:
        return math.pi

    def _apply(self, func: Callable[..., Any], *args: float | Unknown) -> float | Unknown:
        if any(isinstance(a, Unknown) for a in args):
            return _unknown_result(func, args)
        try:
            value = func(*args)
        except (ZeroDivisionError, ValueError):
            raise Refused("is infinite, undefined or not real") from None
        except OverflowError:
            raise Refused(f"number out of range (beyond {MAX_MAGNITUDE:g})") from None
        if isinstance(value, complex):
            raise Refused("power of a negative number is not real")
        return _checked(float(value))

    def binary(
        self, op: type[ast.operator], left: float | Unknown, right: float | Unknown
    ) -> float | Unknown:
        return self._apply(BINARY[op], left, right)

    def negate(self, value: float | Unknown) -> float | Unknown:
        return value if isinstance(value, Unknown) else -value

    def power(self, base: float | Unknown, exponent: float | Unknown) -> float | Unknown:
        return self._apply(operator.pow, base, exponent)

    def call(self, name: str, args: list[float | Unknown]) -> float | Unknown:
        return self._apply(FLOAT_FUNCTIONS[name], *args)

    def scalar(self, value: float | Unknown) -> float | None:
        return None if isinstance(value, Unknown) else value


FLOATS = FloatAlgebra()


def dependencies(value: frozenset[str] | float) -> frozenset[str]:
    """The names a value of :data:`NAMES` depends on (none for a number)."""
    return value if isinstance(value, frozenset) else frozenset()


class NameAlgebra:
    """The set of names an expression depends on (through the values given for the names: a
    definition's set holds the names it is written over); a part without names is its number
    (:data:`FLOATS`), so that a chained constraint keeps its bounds."""

    def number(self, value: int | float) -> float:
        return FLOATS.number(value)

    def constant(self, name: str) -> float:
        return FLOATS.constant(name)

    def _union(self, args: tuple[frozenset[str] | float, ...]) -> frozenset[str]:
        return frozenset().union(*map(dependencies, args))

    def _numbers(self, *args: frozenset[str] | float) -> bool:
        return not any(isinstance(a, frozenset) for a in args)

    def binary(self, op: type[ast.operator], left: Any, right: Any) -> frozenset[str] | float:
        return FLOATS.binary(op, left, right) if self._numbers(left, right) else self._union((left, right))

    def negate(self, value: frozenset[str] | float) -> frozenset[str] | float:
        return FLOATS.negate(value) if self._numbers(value) else value

    def power(self, base: Any, exponent: Any) -> frozenset[str] | float:
        return (
            FLOATS.power(base, exponent) if self._numbers(base, exponent) else self._union((base, exponent))
        )

    def call(self, name: str, args: list[Any]) -> frozenset[str] | float:
        return FLOATS.call(name, args) if self._numbers(*args) else self._union(tuple(args))

    def scalar(self, value: frozenset[str] | float) -> float | None:
        return None if isinstance(value, frozenset) else value


NAMES = NameAlgebra()


@lru_cache(maxsize=4096, typed=True)
def syntax_tree(text: str | float) -> ast.expr:
    """The syntax tree of ``text`` (a number as a constant), within the limits on length and size;
    kept per text and type (the walks never change a tree; ``1``, ``1.0`` and ``True`` are three
    texts), since a backend builds the same terms at every collocation point."""
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
    if sum(1 for _ in ast.walk(tree)) > MAX_EXPRESSION_NODES:
        raise ExpressionError(text[:40] + "...", f"expression has more than {MAX_EXPRESSION_NODES} parts")
    return tree.body


class _Walker:
    def __init__(self, text: str, symbols: Mapping[str, Any], algebra: Algebra) -> None:
        self.text = text
        self.symbols = symbols
        self.algebra = algebra

    def fail(self, node: ast.AST, reason: str) -> ExpressionError:
        return ExpressionError(self.text, reason, getattr(node, "col_offset", None))

    def __call__(self, node: ast.AST) -> Any:
        try:
            return self.value(node)
        except Refused as err:
            raise self.fail(node, str(err)) from None

    def value(self, node: ast.AST) -> Any:
        algebra = self.algebra
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, int | float):
                raise self.fail(node, f"only numbers are allowed as literals, not {node.value!r}")
            return algebra.number(node.value)
        if isinstance(node, ast.Name):
            if node.id in self.symbols:
                return self.symbols[node.id]
            if node.id in CONSTANT_NAMES:
                return algebra.constant(node.id)
            if node.id in FUNCTION_ARITY:
                raise self.fail(node, f"function {node.id!r} used without arguments")
            known = ", ".join(sorted(self.symbols)) or "none"
            raise self.fail(node, f"undefined symbol {node.id!r} (declared: {known})")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            return algebra.power(self(node.left), self(node.right))
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitXor):
            column = self.text.find("^", getattr(node.left, "end_col_offset", 0) or 0)
            raise ExpressionError(self.text, "'^' is not a power: use ** for powers", column)
        if isinstance(node, ast.BinOp) and type(node.op) in BINARY:
            return algebra.binary(type(node.op), self(node.left), self(node.right))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            value = self(node.operand)
            return algebra.negate(value) if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.Call):
            return self.call(node)
        if isinstance(node, ast.Compare):
            raise self.fail(node, "comparisons are only allowed in constraints")
        raise self.fail(node, f"{type(node).__name__} is not allowed")

    def call(self, node: ast.Call) -> Any:
        if not isinstance(node.func, ast.Name):
            raise self.fail(node, "only calls of the whitelisted functions by name are allowed")
        if node.func.id not in FUNCTION_ARITY:
            raise self.fail(node, f"unknown function {node.func.id!r}")
        if node.keywords:
            raise self.fail(node, "keyword arguments are not allowed")
        arity = FUNCTION_ARITY[node.func.id]
        if len(node.args) != arity:
            raise self.fail(node, f"{node.func.id} takes {arity} argument(s), got {len(node.args)}")
        return self.algebra.call(node.func.id, [self(a) for a in node.args])


def expression(text: str | float, symbols: Mapping[str, Any], algebra: Algebra) -> Any:
    """The value of an expression (no comparisons) in ``algebra``, each name taking its value in
    ``symbols``."""
    tree = syntax_tree(text)
    try:
        return _Walker(str(text), symbols, algebra)(tree)
    except RecursionError:
        raise ExpressionError(str(text)[:40] + "...", "expression nested too deeply") from None


@dataclass(frozen=True)
class Relation:
    """``lower <= expr <= upper`` (equality when both bounds are equal); bounds may be infinite."""

    expr: Any
    lower: float
    upper: float

    @property
    def is_equality(self) -> bool:
        return self.lower == self.upper


def relation(text: str, symbols: Mapping[str, Any], algebra: Algebra) -> Relation:
    """A constraint ``a <= b``, ``a >= b``, ``a == b`` or ``lo <= a <= hi`` as a Relation in
    ``algebra``.

    A two-sided chain needs numeric (parameter-free) outer terms; one-sided relations become
    ``a - b`` compared with zero.
    """
    node = syntax_tree(text)
    walk = _Walker(text, symbols, algebra)
    if not isinstance(node, ast.Compare):
        raise ExpressionError(text, "a constraint needs one of <=, >=, ==")
    ops = [type(o) for o in node.ops]
    if not set(ops) <= {ast.LtE, ast.GtE, ast.Eq, ast.Lt, ast.Gt}:
        raise walk.fail(node, "only <=, >=, == (and < >, read as <= >=) are allowed in constraints")
    try:
        terms = [walk(node.left), *(walk(c) for c in node.comparators)]
    except RecursionError:
        raise ExpressionError(text[:40] + "...", "expression nested too deeply") from None
    inf = math.inf
    if len(ops) == 1:
        try:
            diff = algebra.binary(ast.Sub, terms[0], terms[1])
        except Refused as err:
            raise walk.fail(node, str(err)) from None
        if ops[0] is ast.Eq:
            return Relation(diff, 0.0, 0.0)
        if ops[0] in (ast.LtE, ast.Lt):
            return Relation(diff, -inf, 0.0)
        return Relation(diff, 0.0, inf)
    if len(ops) == 2 and ops[0] == ops[1] and ops[0] is not ast.Eq:
        lo, mid, hi = terms
        lo_f, hi_f = algebra.scalar(lo), algebra.scalar(hi)
        if lo_f is None or hi_f is None:
            raise walk.fail(node, "the outer terms of a chained constraint must be numbers")
        if ops[0] in (ast.GtE, ast.Gt):
            lo_f, hi_f = hi_f, lo_f
        if lo_f > hi_f:
            raise walk.fail(node, f"empty range: {lo_f:g} > {hi_f:g}")
        return Relation(mid, lo_f, hi_f)
    raise walk.fail(node, "a constraint is one comparison or a chain lo <= expr <= hi")


def check(text: str | float, names: Iterable[str], *, constraint: bool = False) -> None:
    """Refuse ``text`` (an ExpressionError) unless it is an expression (a constraint when
    ``constraint``) over ``names``, its number-only parts finite and real (:class:`FloatAlgebra`)."""
    unknown = dict.fromkeys(names, UNKNOWN)
    if constraint:
        relation(str(text), unknown, FLOATS)
    else:
        expression(text, unknown, FLOATS)


def numeric_value(text: str | float, values: Mapping[str, float]) -> float:
    """The value of a number-only expression over ``values`` (name → float)."""
    value = expression(text, values, FLOATS)
    if isinstance(value, Unknown):
        raise ExpressionError(str(text), "is not a number here")
    return value


def used_names(text: str | float, names: Mapping[str, frozenset[str]]) -> frozenset[str]:
    """The names ``text`` depends on, each name of ``names`` standing for its set."""
    return dependencies(expression(text, names, NAMES))
