"""The whitelist of the expression language of problem files, without a computer-algebra system
(DESIGN.md, "Expressions are data").

A string is parsed with :mod:`ast` and walked against an explicit whitelist: numbers, declared
names and ``t``, ``+ - * / **``, unary minus, the functions in :data:`FUNCTION_ARITY` and the
constant ``pi``; comparisons only in :func:`relation`, for constraints. Nothing is ever
``eval``-ed; anything else is an :class:`~gamespec.errors.ExpressionError` naming the expression
and the column.

The walk builds its value in an :class:`Algebra`: SymPy (:mod:`gamespec.symbolic.language`, the
form the transforms differentiate, and the canonical form the check at load decides on,
:mod:`gamespec.symbolic.canonical`), floats (:data:`FLOATS`, the values of bounds and parameters,
and the names each term depends on) or a backend's own expressions
(:class:`gamespec.symbolic.library.LibraryAlgebra`, a CasADi graph built straight from the file),
so that one walker decides what an expression may be.
"""

from __future__ import annotations

import ast
import dataclasses
import math
import operator
from abc import ABC, abstractmethod
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


class FileFunction(ABC):
    """A function a problem file defines (a ``tables:`` entry, :mod:`gamespec.symbolic.tables`): the
    value of its name among the symbols of a walk, so that ``CL(mach, alpha)`` is a call the grammar
    knows for that file only; the walk builds it with :meth:`Algebra.tabulated`."""

    name: str

    @property
    @abstractmethod
    def arity(self) -> int:
        """How many arguments it takes."""

    @abstractmethod
    def floats(self, *args: float) -> float:
        """Its value at numbers."""


class Refused(ValueError):
    """Raised by an :class:`Algebra` for a value it will not build; the walker names the column."""


class Algebra(Protocol):
    """Where a walk builds its value: what a number, ``pi``, an operator and a function become.
    A method raises :class:`Refused` for a value it will not build."""

    def number(self, value: int | float) -> Any:
        """A literal of the text."""

    def constant(self, name: str) -> Any:
        """A named constant (``pi``)."""

    def binary(self, op: type[ast.operator], left: Any, right: Any) -> Any:
        """``left op right`` for ``op`` one of :data:`BINARY`."""

    def negate(self, value: Any) -> Any:
        """``-value``."""

    def power(self, base: Any, exponent: Any) -> Any:
        """``base ** exponent``."""

    def call(self, name: str, args: list[Any]) -> Any:
        """The whitelisted function ``name`` (:data:`FUNCTION_ARITY`) of ``args``."""

    def tabulated(self, function: FileFunction, args: list[Any]) -> Any:
        """The file's function ``function`` (a table) of ``args``."""

    def scalar(self, value: Any) -> float | None:
        """``value`` as a float when it is a number (no symbols), else None."""


class VectorAlgebra(Algebra, Protocol):
    """An :class:`Algebra` with vectors (:mod:`gamespec.symbolic.vectors`): it also builds
    ``v[i]``, the list ``[a, b, c]`` and its own functions (``dot``, ``cross``, ``norm``)."""

    functions: Mapping[str, int]
    """The algebra's own functions and their arities, beside :data:`FUNCTION_ARITY`."""

    def index(self, value: Any, i: int) -> Any:
        """Component ``i`` of the vector ``value``."""

    def vector(self, items: list[Any]) -> Any:
        """The vector of ``items``."""


def _checked(value: float) -> float:
    """``value`` when it is a real number within :data:`~gamespec.limits.MAX_MAGNITUDE`."""
    if math.isnan(value):
        raise Refused("is infinite, undefined or not real")
    if not abs(value) <= MAX_MAGNITUDE:
        raise Refused(f"number out of range (beyond {MAX_MAGNITUDE:g})")
    return value


def _atan2(y: float, x: float) -> float:
    """``atan2``, undefined at the origin (SymPy's ``atan2(0, 0)`` is NaN; ``math`` says 0)."""
    if y == 0 and x == 0:
        raise ValueError("atan2(0, 0)")
    return math.atan2(y, x)


def _unit_step(x: float) -> float:
    return 0.5 if x == 0 else float(x > 0)


FLOAT_FUNCTIONS: dict[str, Callable[..., float]] = {
    "sin": math.sin,
    "cos": math.cos,
    "tan": math.tan,
    "asin": math.asin,
    "acos": math.acos,
    "atan": math.atan,
    "atan2": _atan2,
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
class Dependent:
    """A value that depends on ``names`` (through definitions too), whose number is not known: what
    a walk of :data:`FLOATS` gives where a name has no value. It tells the names each term depends
    on (syntactically: ``x - x`` depends on ``x``) and is never refused; whether an expression is
    defined is the load-time check's (:mod:`gamespec.symbolic.canonical`), on a computer-algebra
    system's canonical form."""

    names: frozenset[str]


def unknown(name: str) -> Dependent:
    """The :class:`Dependent` value of a name."""
    return Dependent(frozenset({name}))


def dependencies(value: Any) -> frozenset[str]:
    """The names a value of :data:`FLOATS` depends on (none for a number)."""
    return value.names if isinstance(value, Dependent) else frozenset()


Value = float | Dependent
"""A value of :class:`FloatAlgebra`."""


class FloatAlgebra:
    """Floats, with a :class:`Dependent` for a value that depends on names without numbers: a walk
    over ``{name: float}`` computes an expression (bounds, derived parameters), one over
    ``{name: unknown(name)}`` computes the parts made of numbers only, as a backend's builder does
    (:class:`~gamespec.symbolic.library.LibraryAlgebra`), and tells the names each term depends on.
    A number that is infinite, not real or beyond :data:`~gamespec.limits.MAX_MAGNITUDE` (``1/0``,
    ``log(0)``, ``sqrt(-1)``, ``exp(1000)``) is refused."""

    def number(self, value: int | float) -> float:
        try:
            return _checked(float(value))
        except OverflowError:
            raise Refused(f"number out of range (beyond {MAX_MAGNITUDE:g})") from None

    def constant(self, name: str) -> float:
        return math.pi

    def _apply(self, func: Callable[..., Any], *args: Value) -> Value:
        if any(isinstance(a, Dependent) for a in args):
            return Dependent(frozenset().union(*map(dependencies, args)))
        try:
            value = func(*args)
        except (ZeroDivisionError, ValueError):
            raise Refused("is infinite, undefined or not real") from None
        except OverflowError:
            raise Refused(f"number out of range (beyond {MAX_MAGNITUDE:g})") from None
        if isinstance(value, complex):
            raise Refused("power of a negative number is not real")
        return _checked(float(value))

    def binary(self, op: type[ast.operator], left: Value, right: Value) -> Value:
        return self._apply(BINARY[op], left, right)

    def negate(self, value: Value) -> Value:
        return value if isinstance(value, Dependent) else -value

    def power(self, base: Value, exponent: Value) -> Value:
        return self._apply(operator.pow, base, exponent)

    def call(self, name: str, args: list[Value]) -> Value:
        return self._apply(FLOAT_FUNCTIONS[name], *args)

    def tabulated(self, function: FileFunction, args: list[Value]) -> Value:
        return self._apply(function.floats, *args)

    def scalar(self, value: Value) -> float | None:
        return None if isinstance(value, Dependent) else value


FLOATS = FloatAlgebra()


@dataclass(frozen=True)
class Deferred:
    """A value of :data:`DEFERRED`: one step of a walk of :data:`FLOATS` kept for later, ``step``
    applied to ``args`` (each a :class:`Deferred`, taken first, or a value as it is), or the value of
    the name ``args[0]`` when ``step`` is None. Called with the names' values it computes what the
    walk of :data:`FLOATS` over them computes, without walking the text again (issue 27, item 3),
    with the same refusals: a step's :class:`Refused` is the
    :class:`~gamespec.errors.ExpressionError` the walk names in ``text`` at ``column``. One frame per
    level of the tree, as the walk."""

    step: Callable[..., Any] | None
    args: tuple[Any, ...]
    text: str | None = None
    column: int | None = None

    def __call__(self, values: Mapping[str, Any]) -> Any:
        if self.step is None:
            return values[self.args[0]]
        args = []
        for a in self.args:
            args.append(a(values) if type(a) is Deferred else a)
        try:
            return self.step(*args)
        except Refused as err:
            if self.text is None:
                raise
            raise ExpressionError(self.text, str(err), self.column) from None

    def located(self, text: str, column: int | None) -> Deferred:
        """This step, its refusal named in ``text`` at ``column``."""
        return dataclasses.replace(self, text=text, column=column)


def deferred_name(name: str) -> Deferred:
    """A name's :class:`Deferred` value: its value among those given."""
    return Deferred(None, (name,))


class DeferredAlgebra:
    """An algebra (``base``, :data:`FLOATS` by default), each step kept for later
    (:class:`Deferred`): the walk builds the function of the names' values that a walk of ``base``
    over those values computes. A step it cannot keep (the time of ``x(t=...)`` or a chained
    constraint's outer term that depends on a parameter, which the walk itself needs as a number)
    is refused."""

    def __init__(self, base: Algebra = FLOATS) -> None:
        self.base = base

    def _call(self, name: str, *args: Any) -> Any:
        return self.base.call(name, list(args))

    def _tabulated(self, function: FileFunction, *args: Any) -> Any:
        return self.base.tabulated(function, list(args))

    def number(self, value: int | float) -> Deferred:
        return Deferred(self.base.number, (value,))

    def constant(self, name: str) -> Deferred:
        return Deferred(self.base.constant, (name,))

    def binary(self, op: type[ast.operator], left: Any, right: Any) -> Deferred:
        return Deferred(self.base.binary, (op, left, right))

    def negate(self, value: Any) -> Deferred:
        return Deferred(self.base.negate, (value,))

    def power(self, base: Any, exponent: Any) -> Deferred:
        return Deferred(self.base.power, (base, exponent))

    def call(self, name: str, args: list[Any]) -> Deferred:
        return Deferred(self._call, (name, *args))

    def tabulated(self, function: FileFunction, args: list[Any]) -> Deferred:
        return Deferred(self._tabulated, (function, *args))

    def scalar(self, value: Any) -> float | None:
        """A value the walk needs as a number now: one made of numbers only (an outer term or a
        time that depends on a parameter is refused here)."""
        try:
            number = value({}) if type(value) is Deferred else value
        except KeyError:
            raise Refused("depends on a parameter's value") from None
        return self.base.scalar(number)


DEFERRED = DeferredAlgebra()


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

    def apply(self, node: ast.AST, build: Callable[..., Any], *args: Any) -> Any:
        """``build(*args)`` in the algebra, a refusal named at ``node``'s column (a
        :class:`Deferred` step's refusal too, when it is taken)."""
        try:
            value = build(*args)
        except Refused as err:
            raise self.fail(node, str(err)) from None
        if isinstance(value, Deferred):
            return value.located(self.text, getattr(node, "col_offset", None))
        return value

    def __call__(self, node: ast.AST) -> Any:
        """The value of ``node`` (one frame per level of the tree, as deep sums need)."""
        algebra = self.algebra
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, int | float):
                raise self.fail(node, f"only numbers are allowed as literals, not {node.value!r}")
            return self.apply(node, algebra.number, node.value)
        if isinstance(node, ast.Name):
            if isinstance(self.symbols.get(node.id), FileFunction):
                raise self.fail(node, f"table {node.id!r} used without arguments")
            if node.id in self.symbols:
                return self.symbols[node.id]
            if node.id in CONSTANT_NAMES:
                return algebra.constant(node.id)
            if node.id in FUNCTION_ARITY:
                raise self.fail(node, f"function {node.id!r} used without arguments")
            known = ", ".join(sorted(self.symbols)) or "none"
            raise self.fail(node, f"undefined symbol {node.id!r} (declared: {known})")
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            return self.apply(node, algebra.power, self(node.left), self(node.right))
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitXor):
            column = self.text.find("^", getattr(node.left, "end_col_offset", 0) or 0)
            raise ExpressionError(self.text, "'^' is not a power: use ** for powers", column)
        if isinstance(node, ast.BinOp) and type(node.op) in BINARY:
            return self.apply(node, algebra.binary, type(node.op), self(node.left), self(node.right))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            value = self(node.operand)
            return self.apply(node, algebra.negate, value) if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.Call):
            return self.call(node)
        if isinstance(node, ast.Compare):
            raise self.fail(node, "comparisons are only allowed in constraints")
        if isinstance(node, ast.Attribute):
            return self.dotted(node)
        if isinstance(node, ast.Subscript | ast.List):
            return self.structured(node)
        raise self.fail(node, f"{type(node).__name__} is not allowed")

    def dotted(self, node: ast.Attribute) -> Any:
        """A dotted name (``phases.ascent.x_f``) declared as a whole in the symbols."""
        parts: list[str] = []
        part: ast.expr = node
        while isinstance(part, ast.Attribute):
            parts.append(part.attr)
            part = part.value
        if not isinstance(part, ast.Name):
            raise self.fail(node, "only dotted names are allowed (phases.NAME.x_f)")
        name = ".".join([part.id, *reversed(parts)])
        if name not in self.symbols:
            raise self.fail(node, f"undefined symbol {name!r}")
        return self.symbols[name]

    def structured(self, node: ast.Subscript | ast.List) -> Any:
        """``v[i]`` (``i`` an integer literal) or ``[a, b, c]``: only where the algebra has vectors
        (vector states and controls, ``size:``)."""
        algebra = self.algebra
        if not hasattr(algebra, "index"):
            what = "indexing" if isinstance(node, ast.Subscript) else "a list"
            raise self.fail(node, f"{what} is only allowed over vector states and controls (size: N)")
        if isinstance(node, ast.List):
            return self.apply(node, algebra.vector, [self(e) for e in node.elts])
        index = node.slice
        negative = isinstance(index, ast.UnaryOp) and isinstance(index.op, ast.USub)
        literal = index.operand if isinstance(index, ast.UnaryOp) and negative else index
        if not (isinstance(literal, ast.Constant) and type(literal.value) is int):
            raise self.fail(node, "an index must be an integer literal (r[0])")
        i = -literal.value if negative else literal.value
        return self.apply(node, algebra.index, self(node.value), i)

    def call(self, node: ast.Call) -> Any:
        if not isinstance(node.func, ast.Name):
            raise self.fail(node, "only calls of the whitelisted functions by name are allowed")
        function = self.symbols.get(node.func.id)
        if isinstance(function, FileFunction):
            return self.tabulated(node, function)
        if node.keywords and [k.arg for k in node.keywords] == ["t"] and not node.args:
            return self.at_time(node)
        arities = {**FUNCTION_ARITY, **getattr(self.algebra, "functions", {})}
        if node.func.id not in arities:
            raise self.fail(node, f"unknown function {node.func.id!r}")
        if node.keywords:
            raise self.fail(node, "keyword arguments are not allowed")
        arity = arities[node.func.id]
        if len(node.args) != arity:
            raise self.fail(node, f"{node.func.id} takes {arity} argument(s), got {len(node.args)}")
        return self.apply(node, self.algebra.call, node.func.id, [self(a) for a in node.args])

    def at_time(self, node: ast.Call) -> Any:
        """``x(t=5)``: the value of the name :func:`at_time_name` gives, which the scope holds where
        a value at a fixed time may appear (the states in a boundary constraint); the time must be
        a number."""
        assert isinstance(node.func, ast.Name)
        time = self.apply(node, self.algebra.scalar, self(node.keywords[0].value))
        if time is None:
            raise self.fail(node, f"the time of {node.func.id}(t=...) must be a number")
        name = at_time_name(node.func.id, time)
        if name not in self.symbols:
            reason = "is allowed only for a state in a boundary constraint, at a number (not a parameter)"
            raise self.fail(node, f"{node.func.id}(t=...) {reason}")
        return self.symbols[name]

    def tabulated(self, node: ast.Call, function: FileFunction) -> Any:
        """A call of one of the file's functions (a table), with its arity checked."""
        if node.keywords:
            raise self.fail(node, "keyword arguments are not allowed")
        if len(node.args) != function.arity:
            raise self.fail(node, f"{function.name} takes {function.arity} argument(s), got {len(node.args)}")
        return self.apply(node, self.algebra.tabulated, function, [self(a) for a in node.args])


def at_time(tree: ast.AST) -> list[tuple[str, ast.expr]]:
    """The ``name(t=...)`` calls in a syntax tree: each name and its time's expression."""
    return [
        (node.func.id, node.keywords[0].value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Call)
        and isinstance(node.func, ast.Name)
        and not node.args
        and [k.arg for k in node.keywords] == ["t"]
    ]


def at_time_name(name: str, time: float) -> str:
    """The symbol that stands for ``name`` at ``time`` (``x(t=5)`` → ``x(t=5.0)``), one spelling
    for every way of writing the time."""
    return f"{name}(t={float(time)!r})"


def at_time_parts(name: str) -> tuple[str, float] | None:
    """The name and time of a symbol :func:`at_time_name` spells (``x(t=5.0)`` → ``("x", 5.0)``),
    or None for any other name."""
    base, marker, rest = name.partition("(t=")
    if not marker or not rest.endswith(")"):
        return None
    try:
        time = float(rest[:-1])
    except ValueError:
        return None
    return (base, time) if at_time_name(base, time) == name else None


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
        diff = walk.apply(node, algebra.binary, ast.Sub, terms[0], terms[1])
        if ops[0] is ast.Eq:
            return Relation(diff, 0.0, 0.0)
        if ops[0] in (ast.LtE, ast.Lt):
            return Relation(diff, -inf, 0.0)
        return Relation(diff, 0.0, inf)
    if len(ops) == 2 and ops[0] == ops[1] and ops[0] is not ast.Eq:
        lo, mid, hi = terms
        lo_f, hi_f = (walk.apply(node, algebra.scalar, term) for term in (lo, hi))
        if lo_f is None or hi_f is None:
            raise walk.fail(node, "the outer terms of a chained constraint must be numbers")
        if ops[0] in (ast.GtE, ast.Gt):
            lo_f, hi_f = hi_f, lo_f
        if lo_f > hi_f:
            raise walk.fail(node, f"empty range: {lo_f:g} > {hi_f:g}")
        return Relation(mid, lo_f, hi_f)
    raise walk.fail(node, "a constraint is one comparison or a chain lo <= expr <= hi")


def unknowns(names: Iterable[str]) -> dict[str, Dependent]:
    """Each name as its :class:`Dependent` value: the values of a walk that finds dependencies."""
    return {n: unknown(n) for n in names}


def kept(walk: Callable[[], Any], text: str | float) -> Any:
    """``walk()``, a walk of :data:`DEFERRED`, as its :class:`Deferred` value; None when the walk
    refuses the text (the text is then walked in :data:`FLOATS` each time, which names the
    refusal as before: a text refused at load, or a step :class:`DeferredAlgebra` cannot keep)."""
    try:
        return walk()
    except ExpressionError:
        return None


def taken(value: Any, values: Mapping[str, Any], text: str | float) -> Any:
    """A kept walk (:func:`kept`: a function of the names' values such as a :class:`Deferred`, or a
    value that needs none of them) at ``values``: what the walk of :data:`FLOATS` over them gives."""
    try:
        return value(values) if callable(value) else value
    except RecursionError:
        raise ExpressionError(str(text)[:40] + "...", "expression nested too deeply") from None


def kept_expression(
    text: str | float,
    names: Iterable[str],
    algebra: Algebra = FLOATS,
    tables: Mapping[str, FileFunction] | None = None,
) -> Any:
    """The walk of ``text`` in ``algebra`` over ``names`` (and the file's ``tables``) kept for
    later (:func:`kept`; taken with :func:`taken` at the names' values), None when the walk
    refuses it."""
    deferred = DeferredAlgebra(algebra)
    symbols = {n: deferred_name(n) for n in names} | dict(tables or {})
    return kept(lambda: expression(text, symbols, deferred), text)


def kept_relation(
    text: str,
    names: Iterable[str],
    algebra: Algebra = FLOATS,
    tables: Mapping[str, FileFunction] | None = None,
) -> Relation | None:
    """The walk of the constraint ``text`` in ``algebra`` over ``names`` (and the file's
    ``tables``) kept for later: its expression a kept walk (:func:`kept`), its bounds numbers;
    None when the walk refuses it. Taken with :func:`taken_relation`."""
    deferred = DeferredAlgebra(algebra)
    symbols = {n: deferred_name(n) for n in names} | dict(tables or {})
    found: Relation | None = kept(lambda: relation(text, symbols, deferred), text)
    return found


def taken_relation(value: Relation, values: Mapping[str, Any], text: str) -> Relation:
    """A kept relation (:func:`kept_relation`) at ``values``: the relation the walk of its algebra
    over them gives."""
    return Relation(taken(value.expr, values, text), value.lower, value.upper)


@lru_cache(maxsize=4096, typed=True)
def _kept_value(text: str | float, names: tuple[str, ...]) -> Any:
    """The walk of ``text`` over ``names`` kept once per text and names (:func:`numeric_value`)."""
    return kept_expression(text, names)


def numeric_value(text: str | float, values: Mapping[str, float]) -> float:
    """The value of a number-only expression over ``values`` (name → float): the text is walked
    once per set of names (:func:`_kept_value`), then evaluated at each ``values``."""
    walked = _kept_value(text, tuple(sorted(values)))
    value = expression(text, values, FLOATS) if walked is None else taken(walked, values, text)
    if isinstance(value, Dependent):
        raise ExpressionError(str(text), "is not a number here")
    number: float = value
    return number
