"""The printer writes SymPy back to the language: ``parse(to_text(e)) == e`` over random expression
trees and over their derivatives (which bring ``sign``, ``heaviside``, ``abs``, ``min``, ``max``),
and what the language cannot hold is refused in one line."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from gamespec.errors import ExpressionError
from gamespec.symbolic.language import FUNCTIONS, float_value, parse, parse_relation, symbol
from gamespec.symbolic.library import NUMPY
from gamespec.symbolic.printer import to_text
from gamespec.symbolic.translate import translate

SYMBOLS = {name: symbol(name) for name in ("x", "y", "t")}
X, Y, T = SYMBOLS.values()

numbers = st.one_of(
    st.integers(-20, 20).map(sp.Integer),
    st.fractions(max_denominator=12).map(lambda f: sp.Rational(f.numerator, f.denominator)),
    st.floats(-10.0, 10.0, allow_nan=False).map(sp.Float),
    st.sampled_from([sp.pi, sp.E]),
)
leaves = st.one_of(st.sampled_from([X, Y, T]), numbers)

Unary = Callable[[sp.Expr], sp.Expr]
Binary = Callable[[sp.Expr, sp.Expr], sp.Expr]

REAL_UNARY: list[Unary] = [
    sp.sin,
    sp.cos,
    sp.tan,
    sp.atan,
    sp.exp,
    sp.tanh,
    sp.Abs,
    lambda a: sp.sqrt(1 + a**2),
    lambda a: sp.log(1 + a**2),
    lambda a: -a,
    lambda a: a**2,
    lambda a: a**3,
]
"""Functions SymPy knows to stay real over real arguments, so that derivatives of ``abs`` are
``sign`` (not ``re``/``im``)."""
REAL_BINARY: list[Binary] = [
    lambda a, b: a + b,
    lambda a, b: a - b,
    lambda a, b: a * b,
    lambda a, b: a / (1 + b**2),
    sp.Min,
    sp.Max,
    sp.atan2,
]
MORE_UNARY: list[Unary] = [
    sp.asin,
    sp.acos,
    sp.sign,
    sp.Heaviside,
    sp.sqrt,
    sp.log,
    lambda a: a ** sp.Rational(1, 3),
    lambda a: a**-1,
    lambda a: a ** sp.Float(2.5),
]
MORE_BINARY: list[Binary] = [lambda a, b: a / b, lambda a, b: a ** sp.tanh(b)]


def tame(arg: sp.Expr) -> bool:
    """A sub-tree fit to build on: its exact numbers short and, when it is a number, of magnitude
    below 1000 (exp(exp(exp(20))) and long powers would have SymPy evaluate for minutes)."""
    if any(max(abs(r.p), r.q).bit_length() > 200 for r in arg.atoms(sp.Rational)):
        return False
    if arg.free_symbols:
        return True
    try:
        return abs(complex(arg.evalf(15))) < 1e3
    except (TypeError, ValueError, OverflowError):
        return False


def apply(func: Callable[..., sp.Expr], *args: sp.Expr) -> sp.Expr:
    """``func(*args)``, or NaN (filtered out by :func:`representable`) where an argument is not
    :func:`tame`, SymPy's floating-point arithmetic raises (a float divided by 0.0), a function
    refuses a complex argument or SymPy fails inside its own evaluation (``AttributeError``, a
    comparison with NaN)."""
    if not all(map(tame, args)):
        return sp.nan
    try:
        return func(*args)
    except (ZeroDivisionError, OverflowError, ValueError, TypeError, AttributeError):
        return sp.nan


def trees(unary: list[Unary], binary: list[Binary]) -> st.SearchStrategy[sp.Expr]:
    def extend(children: st.SearchStrategy[sp.Expr]) -> st.SearchStrategy[sp.Expr]:
        return st.one_of(
            st.builds(apply, st.sampled_from(unary), children),
            st.builds(apply, st.sampled_from(binary), children, children),
        )

    return st.recursive(leaves, extend, max_leaves=12)


def representable(expr: sp.Expr) -> bool:
    """Finite (no infinities, no bounds such as ``atan(zoo)``), real, no ``Piecewise``, only the
    language's functions, every float
    within double precision, every power of two numbers real and every number-valued part within
    double range (:func:`float_value`): what the language can hold."""
    if expr.has(sp.zoo, sp.oo, -sp.oo, sp.nan, sp.I, sp.AccumBounds, sp.Piecewise):
        return False
    language = {func for _, func in FUNCTIONS.values()}
    if any(part.func not in language for part in expr.atoms(sp.Function)):
        return False  # e.g. cos(sqrt(-1)) evaluates to cosh(1), which the language has no name for
    if not all(math.isfinite(float(f)) and sp.Float(float(f)) == f for f in expr.atoms(sp.Float)):
        return False
    if any(max(abs(r.p), r.q).bit_length() > 1_000 for r in expr.atoms(sp.Rational)):
        return False
    for power in expr.atoms(sp.Pow):
        if power.base.is_number and power.exp.is_number:
            try:
                value = float(power.base) ** float(power.exp)
            except (OverflowError, ZeroDivisionError, TypeError):
                return False
            if isinstance(value, complex):
                return False
    for part in sp.preorder_traversal(expr):
        if part.is_number:
            try:
                float_value(part)
            except OverflowError:
                return False
            except (ValueError, TypeError, RecursionError):
                pass
    return True


SETTINGS = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])


def canonical(expr: sp.Basic) -> sp.Basic:
    """``expr`` rebuilt with evaluation: SymPy sometimes leaves a product nested in a product
    (``sqrt(3*sqrt(46)/2)``), which no parse can produce; its canonical form is what must return."""
    return expr.func(*map(canonical, expr.args)) if expr.args else expr


def assert_round_trip(expr: sp.Expr) -> None:
    text = to_text(expr)
    assert parse(text, SYMBOLS) == canonical(expr), text


@settings(SETTINGS, max_examples=150)
@given(trees(REAL_UNARY + MORE_UNARY, REAL_BINARY + MORE_BINARY))
def test_round_trip_of_random_trees(expr: sp.Expr) -> None:
    assume(representable(expr))
    assert_round_trip(expr)


@SETTINGS
@given(trees(REAL_UNARY, REAL_BINARY), st.sampled_from([X, Y, T]))
def test_round_trip_of_derivatives(expr: sp.Expr, wrt: sp.Symbol) -> None:
    """First and second derivatives: sign, heaviside, abs, min and max print and parse back."""
    assume(representable(expr))
    first = sp.diff(expr, wrt)
    assume(representable(first))
    assert_round_trip(first)
    second = sp.diff(first, wrt)
    # sign's derivative is a DiracDelta (zero almost everywhere), which the language has no form for;
    # SymPy leaves it as an unevaluated Derivative when it cannot prove sign's argument real.
    assume(not second.has(sp.DiracDelta, sp.Derivative) and representable(second))
    assert_round_trip(second)


@pytest.mark.parametrize(
    ("expr", "appears"),
    [
        (sp.diff(sp.Abs(X - Y), X), "sign(x - y)"),
        (sp.diff(sp.Max(X, Y**2), Y), "heaviside("),
        (sp.diff(sp.Min(X, Y, T), X), "min("),
        (sp.Max(X, Y, T, 2), "max("),
        (sp.E * X + sp.pi, "exp(1)"),
        (sp.Rational(-3, 7) * X, "3*x/7"),
        (X ** sp.Rational(2, 3), "x**(2/3)"),
        (sp.Float(0.1) * X, "0.1*x"),
        (sp.Float(1 / 3) + X, repr(1 / 3)),
    ],
)
def test_language_names_and_exact_numbers(expr: sp.Expr, appears: str) -> None:
    text = to_text(expr)
    assert appears in text
    assert parse(text, SYMBOLS) == expr


@given(st.floats(allow_nan=False, allow_infinity=False))
def test_floats_round_trip_bit_for_bit(value: float) -> None:
    assert float(parse(to_text(sp.Float(value) * X), SYMBOLS).coeff(X)) == value or value == 0.0


@pytest.mark.parametrize(
    ("relation", "text"),
    [
        (sp.Le(sp.Rational(1, 2) * (X**2 - Y**2), 0), "0.5*(x**2 - y**2) <= 0"),
        (sp.Ge(sp.sin(X), sp.cos(Y)), "sin(x) >= cos(y)"),
        (sp.Eq(X, 2 * Y), "x == 2*y"),
        (sp.Lt(sp.Abs(X), 1), "abs(x) <= 1"),
    ],
)
def test_relations_print_for_constraints(relation: sp.Basic, text: str) -> None:
    printed = parse_relation(to_text(relation), SYMBOLS)
    expected = parse_relation(text, SYMBOLS)
    assert (printed.lower, printed.upper) == (expected.lower, expected.upper)
    assert sp.simplify(printed.expr - expected.expr) == 0


@pytest.mark.parametrize(
    ("expr", "reason"),
    [
        (sp.Piecewise((X, X > 0), (0, True)), "Piecewise"),
        (sp.diff(sp.sign(X), X), "DiracDelta"),
        (sp.sinh(X), "sinh"),
        (sp.Heaviside(X, 0), "heaviside"),
        (sp.oo * X, "Infinity"),
        (sp.Float("1e400") * X, "range of a double"),
        (sp.Float("1e-400") * X, "range of a double"),
        (sp.Float(2.0**-1030) * sp.Float(1 / 3) * X, "range of a double"),
        (sp.Symbol("sin") + X, "sin"),
        (sp.Function("f")(X), "f"),
        (sp.Ne(X, Y), "Unequality"),
    ],
)
def test_what_the_language_cannot_hold_is_refused(expr: sp.Basic, reason: str) -> None:
    with pytest.raises(ExpressionError, match=reason):
        to_text(expr)


def test_printed_derivative_evaluates_like_sympy() -> None:
    """heaviside(0) = 1/2 and sign(0) = 0 in the NumPy translation, as in SymPy."""
    expr = sp.diff(sp.Max(X, Y) + sp.Abs(X - 1), X)
    parsed = parse(to_text(expr), SYMBOLS)
    for x, y in [(0.0, 0.0), (1.0, 0.0), (2.0, 3.0), (1.0, 1.0)]:
        expected = float(expr.subs({X: x, Y: y}))
        got = float(translate(parsed, {X: np.float64(x), Y: np.float64(y)}, NUMPY))
        assert got == pytest.approx(expected, abs=1e-15)
