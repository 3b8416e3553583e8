"""The check at load of an expression of a problem file: it is refused exactly when the solve path
would refuse it (DESIGN.md, "Expressions are data": what ``validate`` accepts, the solve path
accepts).

The solve path builds an expression twice: a backend's builder straight from the text
(:class:`~gamespec.symbolic.library.LibraryAlgebra`, which computes the parts made of numbers
only in floats, :data:`~gamespec.symbolic.grammar.FLOATS`) and SymPy, for the transforms, which
differentiate it (:mod:`gamespec.symbolic.language`; SymPy's canonical form, in which ``x - x`` is
0, ``2*(x + y) - 2*x - 2*y`` is 0, ``sqrt(x**2) - abs(x)`` is 0 for a real ``x``, and so
``1/(...)`` of any of them is infinite). :func:`check` refuses what either refuses, and what has a
derivative SymPy finds undefined (``0**x``, whose derivative holds ``log(0)``).

SymPy is a computer-algebra system whose import costs more than loading and solving a small problem
(about 0.3 s of CPU), so it is asked only about the texts a screen cannot settle: the
:class:`Screen` walks the text without SymPy and proves that SymPy's canonical form holds no
undefined value — every operation in it is defined for every real argument (``+ - *``, a power by a
nonnegative integer, a division by a nonzero literal, ``sin``, ``exp``, ``abs``, ``max``, ...) and
every number its canonical form can hold is bounded far below
:data:`~gamespec.limits.MAX_MAGNITUDE` — or raises :class:`Undecided`, and SymPy decides. The
screen never decides a refusal: it cancels nothing and predicts no simplification.

SymEngine was measured as the faster CAS for this and not taken: its canonical form is weaker than
SymPy's (it keeps ``2*(x + y) - 2*x - 2*y``, ``x + y - (x + y)``, ``sqrt(x**2) - abs(x)``,
``min(x, x + 1)`` and ``atan(-x) + atan(x)``, all of which SymPy folds), so a check on it would
accept texts the solve path, on SymPy, refuses.
"""

from __future__ import annotations

import ast
import math
import threading
from collections import OrderedDict
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from gamespec.errors import ExpressionError
from gamespec.limits import MAX_MAGNITUDE
from gamespec.symbolic.grammar import (
    DEFERRED,
    FLOATS,
    Deferred,
    FileFunction,
    Refused,
    deferred_name,
    expression,
    kept,
    relation,
    syntax_tree,
    taken,
    unknown,
)

SCREEN_LIMIT = MAX_MAGNITUDE * 2.0**-64
"""The largest bound the screen settles: far enough below the range of a double that its own
rounding (relative ``2**-53`` a step, at most a few thousand steps) cannot reach the range."""
EXACT_INTEGERS = 2**53
"""Integer literals up to this magnitude are the same number as a double and in SymPy."""
TOTAL_FUNCTIONS = frozenset({"sin", "cos", "exp", "tanh", "atan", "abs", "min", "max", "sign", "heaviside"})
"""The whitelisted functions defined, finite and real for every real argument (and so is their
derivative where SymPy writes one: ``abs`` → ``sign``, ``max`` → ``heaviside``)."""
ATOM_FUNCTIONS = frozenset({"log", "sqrt", "tan", "asin", "acos"})
"""The whitelisted functions SymPy keeps, with their derivatives, as functions of ``c*name`` (a real
symbol of unknown sign: ``log(-2*x)``, ``sqrt(-x)``, ``tan(x)``), not known to be real there."""
REAL_ARGUMENTS = frozenset({"abs", "sign", "min", "max", "heaviside"})
"""The functions whose SymPy derivative is in the language only for an argument SymPy knows to be
real (``abs(x)`` → ``sign(x)``; ``abs(asin(x))`` → ``re``, ``im``)."""


class Undecided(Exception):
    """Raised by the :class:`Screen` for a text it cannot prove defined: SymPy decides."""


@dataclass(frozen=True)
class Bounded:
    """A value of the :class:`Screen`: ``bound`` is at least the magnitude of every number SymPy's
    canonical form of it, and of each of its parts, can hold; ``value`` its float when it is made
    of numbers only (None when it depends on a name), ``exact`` when that float is SymPy's number
    itself (a literal, ``pi``, their negation). ``power`` is ``k`` when SymPy's form is
    ``c*name**k`` for an exact nonzero ``c`` and a nonzero integer ``k`` (so never a number and never
    zero, whatever the name's value), else 0. ``real`` when SymPy knows its form to be real for every
    real value of the names."""

    bound: float
    value: float | None = None
    exact: bool = False
    power: int = 0
    real: bool = True


class Screen:
    """The grammar's walk proving, without SymPy, that an expression's SymPy form and its derivatives
    are defined: it raises :class:`Undecided` at an operation that could be undefined for some
    argument — a division by anything but a nonzero literal or ``c*name**k``; ``log``, ``sqrt``,
    ``tan``, ``asin`` or ``acos`` of anything but ``c*name``; ``atan2``; a power of ``c*name`` by
    anything but a literal, of ``c*name**k`` by anything but an integer literal, of anything else by
    anything but a nonnegative integer literal; a function of numbers other than literals — and at a
    bound beyond :data:`SCREEN_LIMIT`."""

    def number(self, value: int | float) -> Bounded:
        try:
            number = float(value)
        except OverflowError:
            raise Undecided from None
        exact = isinstance(value, float) or abs(value) <= EXACT_INTEGERS
        return self._bounded(max(1.0, abs(number)), number, exact)

    def constant(self, name: str) -> Bounded:
        return Bounded(math.pi, math.pi, exact=True)

    @staticmethod
    def _bounded(
        bound: float,
        value: float | None = None,
        exact: bool = False,
        *parts: Bounded,
        power: int = 0,
        real: bool = True,
    ) -> Bounded:
        bound = max(bound, *(p.bound for p in parts)) if parts else bound
        if not bound <= SCREEN_LIMIT or (value is not None and not abs(value) <= SCREEN_LIMIT):
            raise Undecided
        return Bounded(bound, value, exact, power, real and all(p.real for p in parts))

    @staticmethod
    def _float(build: Any, *args: Any) -> float:
        """A part made of numbers only, computed in floats (refused there by the float walk of
        :func:`check` already; here it only needs its value)."""
        try:
            return float(build(*args))
        except (Refused, ArithmeticError, ValueError, TypeError):
            raise Undecided from None

    @staticmethod
    def _nonzero_literal(value: Bounded) -> bool:
        return value.exact and bool(value.value)

    def binary(self, op: type[ast.operator], left: Bounded, right: Bounded) -> Bounded:
        power, real = 0, True
        if op is ast.Div:
            if not (self._nonzero_literal(right) or right.power):
                raise Undecided
            bound = left.bound * right.bound * (1.0 / abs(right.value) if right.value else 1.0)
            power = left.power if self._nonzero_literal(right) else 0
            real = self._nonzero_literal(right)
        elif op is ast.Mult:
            bound = left.bound * right.bound
            if self._nonzero_literal(left) or self._nonzero_literal(right):
                power = left.power or right.power
        else:
            bound = left.bound + right.bound
        value = None
        if left.value is not None and right.value is not None:
            value = self._float(FLOATS.binary, op, left.value, right.value)
        return self._bounded(bound, value, False, left, right, power=power, real=real)

    def negate(self, value: Bounded) -> Bounded:
        number = None if value.value is None else -value.value
        return Bounded(value.bound, number, value.exact, value.power, value.real)

    def power(self, base: Bounded, exponent: Bounded) -> Bounded:
        e = exponent.value
        if e is None or not exponent.exact:
            raise Undecided
        if base.value is not None:
            if not base.exact:
                raise Undecided
            value = self._float(FLOATS.power, base.value, e)
            return self._bounded(max(1.0, abs(value)), value, False, base, exponent)
        integer = e.is_integer()
        if not (base.power == 1 or (base.power and integer) or (integer and e >= 0)):
            raise Undecided
        try:
            bound = max(2.0, base.bound) ** abs(e)
        except OverflowError:
            raise Undecided from None
        power = int(base.power * e) if base.power and integer and e else 0
        return self._bounded(bound, None, False, base, exponent, power=power, real=integer and e >= 0)

    def call(self, name: str, args: list[Bounded]) -> Bounded:
        if all(a.value is not None and a.exact for a in args):
            value = self._float(FLOATS.call, name, [a.value for a in args])
            return self._bounded(max(1.0, abs(value)), value, False, *args)
        atom = len(args) == 1 and args[0].power == 1
        if name not in TOTAL_FUNCTIONS and not (atom and name in ATOM_FUNCTIONS):
            raise Undecided
        if name in REAL_ARGUMENTS and not all(a.real for a in args):
            raise Undecided
        largest = max(math.pi, *(a.bound for a in args))
        value = None
        if all(a.value is not None for a in args):
            value = self._float(FLOATS.call, name, [a.value for a in args])
        if name == "exp":
            try:
                largest = math.exp(largest)
            except OverflowError:
                raise Undecided from None
        return self._bounded(largest, value, False, *args, real=name not in ATOM_FUNCTIONS)

    def tabulated(self, function: FileFunction, args: list[Bounded]) -> Bounded:
        """A table: defined, finite and real for every real argument, as its derivatives (an
        interpolant of finite data, :mod:`gamespec.symbolic.tables`)."""
        if all(a.value is not None and a.exact for a in args):
            value = self._float(FLOATS.tabulated, function, [a.value for a in args])
            return self._bounded(max(1.0, abs(value)), value, False, *args)
        if not all(a.real for a in args):
            raise Undecided
        value = None
        if all(a.value is not None for a in args):
            value = self._float(FLOATS.tabulated, function, [a.value for a in args])
        return self._bounded(max(math.pi, *(a.bound for a in args)), value, False, *args)

    def scalar(self, value: Bounded) -> float | None:
        """An outer term of a chained constraint: a number the same in floats and in SymPy."""
        if value.value is None or not value.exact:
            raise Undecided
        return value.value


SCREEN = Screen()
NAME = Bounded(1.0, power=1)
"""A name's value in the screen (a real symbol: ``1*name**1``)."""


def check(
    text: str | float,
    names: Iterable[str],
    values: Mapping[str, float] | None = None,
    *,
    constraint: bool = False,
    definitions: Mapping[str, str | float] | None = None,
    functions: Mapping[str, FileFunction] | None = None,
) -> None:
    """Refuse ``text`` (an ExpressionError) unless it is an expression (a constraint when
    ``constraint``) over ``names``, the parameters among them at their ``values`` and each of
    ``definitions`` (in order, over the names and the definitions before it) standing for its
    expression, whose solve path is defined: its parts made of numbers finite and real in floats, as
    a backend builds them, and its SymPy form (every name a real symbol) and that form's first
    derivatives finite and real. ``functions`` are the file's tables by name
    (:mod:`gamespec.symbolic.tables`)."""
    values = dict(values or {})
    names = [*dict.fromkeys([*names, *values])]
    definitions = _used(text, dict(definitions or {}))
    used = _names(text).union(*map(_names, definitions.values()))
    tables = {n: f for n, f in (functions or {}).items() if n in used}
    valued = tuple(n for n in names if n in values)
    scope = (tuple(names), valued, constraint, tuple(definitions.items()), _tables_key(tables))
    key = (type(text), text, *scope)
    kept = _kept_check(key, tables)
    if kept.floats is None:
        floats = {n: values[n] if n in values else unknown(n) for n in names}
        _walk(text, floats | tables, FLOATS, constraint, definitions)
    else:
        taken(kept.floats, {n: values[n] for n in valued}, text)
    if not kept.defined:
        try:
            _walk(text, dict.fromkeys(names, NAME) | tables, SCREEN, constraint, definitions)
        except Undecided:
            _check_in_sympy(text, names, constraint, definitions, tables)
        kept.defined = True


@dataclass
class _KeptCheck:
    """What :func:`check` keeps of a text over one scope: its walk in floats as a function of the
    parameters' values (:class:`~gamespec.symbolic.grammar.Deferred`; None: walked each time), and
    whether its solve path was found defined, which does not depend on those values (the screen
    and SymPy see every name as a symbol): a check at new parameter values walks no text (issue 27,
    item 3)."""

    floats: Any
    defined: bool = False


_KEPT: OrderedDict[tuple[Any, ...], _KeptCheck] = OrderedDict()
_KEPT_LOCK = threading.Lock()
"""Held while :data:`_KEPT` changes (a study's threads check at once)."""
KEPT_CHECKS = 4096
"""How many texts-over-a-scope :func:`check` keeps (the least recently used go first)."""


def _tables_key(tables: Mapping[str, FileFunction]) -> tuple[Any, ...]:
    """The tables a text uses as part of a kept check's key: a table by its data (a spec validated
    again at new parameter values rebuilds its tables, with the same data), another file
    function by itself (NumPy is imported only for a text that uses a table: validating a file
    without tables imports none, ``tests/core/test_startup_imports.py``)."""
    if not tables:
        return ()
    import numpy as np

    def data(function: FileFunction) -> Any:
        axes, values = getattr(function, "axes", None), getattr(function, "values", None)
        if axes is None or values is None:
            return function
        arrays = [np.asarray(a, dtype=float) for a in (*axes, values)]
        return (getattr(function, "method", None), *((a.shape, a.tobytes()) for a in arrays))

    return tuple((name, data(function)) for name, function in tables.items())


def _kept_check(key: tuple[Any, ...], tables: Mapping[str, FileFunction]) -> _KeptCheck:
    """The kept check of ``key`` (text, names, those with values, constraint, definitions, the
    tables the text uses, :func:`_tables_key`), walked in
    :data:`~gamespec.symbolic.grammar.DEFERRED` on first use."""
    with _KEPT_LOCK:
        if key in _KEPT:
            _KEPT.move_to_end(key)
            return _KEPT[key]
    _, text, names, valued, constraint, definitions, _ = key
    symbols = {n: deferred_name(n) if n in valued else unknown(n) for n in names}
    walked = kept(lambda: _kept_walk(text, symbols | dict(tables), constraint, dict(definitions)), text)
    found = _KeptCheck(walked)
    with _KEPT_LOCK:
        _KEPT[key] = found
        if len(_KEPT) > KEPT_CHECKS:
            _KEPT.popitem(last=False)
    return found


def _used(text: str | float, definitions: dict[str, str | float]) -> dict[str, str | float]:
    """The definitions ``text`` uses, directly or through other definitions, in their order."""
    used = _names(text)
    for name in reversed(definitions):
        if name in used:
            used |= _names(definitions[name])
    return {n: raw for n, raw in definitions.items() if n in used}


def _names(text: str | float) -> set[str]:
    return {n.id for n in ast.walk(syntax_tree(text)) if isinstance(n, ast.Name)}


def _walk(
    text: str | float, symbols: dict[str, Any], algebra: Any, constraint: bool, definitions: Mapping[str, Any]
) -> Any:
    """The value of ``text`` in ``algebra`` (its expression, for a constraint), the definitions
    built first over ``symbols``, as :class:`~gamespec.ocp.symbolic.SymbolicOcp` builds them."""
    scope = dict(symbols)
    for name, raw in definitions.items():
        scope[name] = expression(raw, scope, algebra)
    return relation(str(text), scope, algebra).expr if constraint else expression(text, scope, algebra)


def _kept_walk(
    text: str | float, symbols: dict[str, Any], constraint: bool, definitions: Mapping[str, Any]
) -> Callable[[Mapping[str, Any]], Any]:
    """:func:`_walk` in :data:`~gamespec.symbolic.grammar.DEFERRED`: taken at values, it computes
    the definitions in their order, each once, then ``text``, as :func:`_walk` in floats does."""
    scope = dict(symbols)
    steps = []
    for name, raw in definitions.items():
        steps.append((name, expression(raw, scope, DEFERRED)))
        scope[name] = deferred_name(name)
    last = relation(str(text), scope, DEFERRED).expr if constraint else expression(text, scope, DEFERRED)

    def run(values: Mapping[str, Any]) -> Any:
        scope = dict(values)
        for name, step in steps:
            scope[name] = step(scope) if type(step) is Deferred else step
        return last(scope) if type(last) is Deferred else last

    return run


def _check_in_sympy(
    text: str | float,
    names: list[str],
    constraint: bool,
    definitions: Mapping[str, str | float],
    tables: Mapping[str, FileFunction],
) -> None:
    """The SymPy form of ``text`` (refused there as :mod:`gamespec.symbolic.language` refuses), and
    its first derivatives in each of its names finite, real and in the language (SymPy's own
    derivatives: ``abs`` → ``sign``, ``max(a, b)`` → ``heaviside(a - b)``; ``DiracDelta``, the
    derivative of ``sign`` and ``heaviside``, as well; not ``re``, ``im`` or an unevaluated
    ``Derivative``, which SymPy writes for ``abs(asin(x))``)."""
    import sympy as sp

    from gamespec.symbolic.language import FUNCTIONS, SYMPY, symbol
    from gamespec.symbolic.tables import TabulatedSympy

    functions = (f for _, f in FUNCTIONS.values() if isinstance(f, type))
    nodes = (sp.Symbol, sp.Number, sp.NumberSymbol, sp.Add, sp.Mul, sp.Pow, sp.DiracDelta, *functions)
    nodes = (*nodes, TabulatedSympy.base())
    expr = _walk(text, {n: symbol(n) for n in names} | dict(tables), SYMPY, constraint, definitions)
    for name in sorted(expr.free_symbols, key=str):
        try:
            derivative = SYMPY.finite(sp.diff(expr, name))
            foreign = next((n for n in sp.preorder_traversal(derivative) if not isinstance(n, nodes)), None)
        except Refused as err:
            raise ExpressionError(str(text), f"its derivative in {name} {err}") from None
        except RecursionError:
            raise ExpressionError(str(text)[:40] + "...", "expression nested too deeply") from None
        if foreign is not None:
            kind = type(foreign).__name__
            raise ExpressionError(str(text), f"its derivative in {name} holds {kind}, not in the language")
