"""The expression whitelist (DESIGN.md): what parses, what is rejected and where."""

from __future__ import annotations

import math

import pytest
import sympy as sp
from hypothesis import given
from hypothesis import strategies as st

from gamespec.errors import ExpressionError
from gamespec.symbolic.language import parse, parse_relation, symbol
from gamespec.symbolic.translate import numeric

SYMBOLS = {n: symbol(n) for n in ("x", "y", "v")} | {"t": symbol("t")}


@pytest.mark.parametrize(
    "text",
    [
        '__import__("os").system("true")',
        "x.real",
        "x[0]",
        "(lambda: 1)()",
        "'text'",
        'f"{x}"',
        "foo(x)",
        "open('f')",
        "x if y else v",
        "[x, y]",
        "x and y",
        "x == y",
        "sin(x=1)",
        "sin(x, y)",
        "undefined + 1",
        "True",
        "x @ y",
        "x // y",
        "x % y",
        "sin",
    ],
)
def test_rejects_everything_outside_the_whitelist(text: str) -> None:
    with pytest.raises(ExpressionError) as info:
        parse(text, SYMBOLS)
    assert text in str(info.value)
    assert "column" in str(info.value)


def test_syntax_error_names_the_column() -> None:
    with pytest.raises(ExpressionError, match="column"):
        parse("x +* y", SYMBOLS)


def test_whitelisted_functions_match_math() -> None:
    text = "sin(x) + cos(y) * tan(v) - asin(0.5) + acos(0.2) + atan(x) + atan2(y, x) + exp(v)"
    text += " + log(2) + sqrt(v) + abs(-x) + tanh(y) + min(x, y) - max(x, v) + pi + t**2 - -x / 2"
    expr = parse(text, SYMBOLS)
    x, y, v, t = 0.3, -1.2, 0.7, 2.0
    expected = (
        math.sin(x)
        + math.cos(y) * math.tan(v)
        - math.asin(0.5)
        + math.acos(0.2)
        + math.atan(x)
        + math.atan2(y, x)
        + math.exp(v)
        + math.log(2)
        + math.sqrt(v)
        + abs(-x)
        + math.tanh(y)
        + min(x, y)
        - max(x, v)
        + math.pi
        + t**2
        + x / 2
    )
    values = {symbol("x"): x, symbol("y"): y, symbol("v"): v, symbol("t"): t}
    assert numeric(expr, values) == pytest.approx(expected, rel=1e-12)


@given(st.floats(-5, 5), st.floats(-5, 5))
def test_parsed_polynomial_evaluates_like_python_arithmetic(a: float, b: float) -> None:
    expr = parse("x**2 - 3*x*y + y/4 - 1", SYMBOLS)
    got = numeric(expr, {symbol("x"): a, symbol("y"): b})
    assert got == pytest.approx(a**2 - 3 * a * b + b / 4 - 1, rel=1e-9, abs=1e-9)


@pytest.mark.parametrize(
    ("text", "lower", "upper"),
    [
        ("x <= 1", -math.inf, 0.0),
        ("x >= y", 0.0, math.inf),
        ("x == 2", 0.0, 0.0),
        ("0 <= x <= 3", 0.0, 3.0),
        ("3 >= x >= -1", -1.0, 3.0),
    ],
)
def test_relations(text: str, lower: float, upper: float) -> None:
    rel = parse_relation(text, SYMBOLS)
    assert (rel.lower, rel.upper) == (lower, upper)
    assert rel.expr.free_symbols <= {symbol("x"), symbol("y")}


def test_relation_needs_a_comparison_and_numeric_outer_terms() -> None:
    with pytest.raises(ExpressionError, match="needs one of"):
        parse_relation("x + 1", SYMBOLS)
    with pytest.raises(ExpressionError, match="outer terms"):
        parse_relation("y <= x <= 1", SYMBOLS)


def test_symbols_are_real() -> None:
    assert parse("x", SYMBOLS).is_real
    assert sp.simplify(parse("sqrt(x**2)", SYMBOLS) - sp.Abs(symbol("x"))) == 0


@pytest.mark.parametrize(
    "text", ["9**9**9", "sin(x)**2**2**2**2**2**2**2", "1/0", "log(0)", "sqrt(-1)", "(-2)**0.5"]
)
def test_numbers_that_are_not_finite_reals_are_rejected_fast(text: str) -> None:
    with pytest.raises(ExpressionError):
        parse(text, SYMBOLS)


def test_deep_nesting_is_an_expression_error() -> None:
    with pytest.raises(ExpressionError, match=r"nested too deeply|parts"):
        parse("-" * 5000 + "x", SYMBOLS)
    with pytest.raises(ExpressionError):
        parse("+".join(["x"] * 3000), SYMBOLS)
