"""The calculus helpers against central finite differences: the Jacobian of nonlinear maps at
random points, and the linearization along a trajectory (eqs. 5.5–5.6).

A central difference with step h errs by h²/6·|f'''| (truncation) plus about ε|f|/h (rounding);
with h = 1e-5 and the O(1) maps below both stay under 1e-9, so the tolerance 1e-7 cannot be met
by a wrong derivative and is not at the mercy of rounding.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from gamespec.errors import ExpressionError
from gamespec.symbolic.calculus import gradient, jacobian, linearize, numeric_function
from gamespec.symbolic.language import parse, symbol

STEP = 1e-5
TOL = 1e-7
NAMES = ("x", "y", "z")
SYMS = [symbol(n) for n in NAMES]
SYMBOLS = dict(zip(NAMES, SYMS, strict=True)) | {"t": symbol("t"), "v": symbol("v")}

MAPS = [
    ["x*y*cos(z) - sin(x)", "exp(-x**2/4)*atan(y) + z**3/10", "tanh(x*y - z)"],
    ["v*cos(z - x) - sqrt(4 - v**2*sin(z - x)**2)", "v*sin(z - x)/(2 + y**2)"],
    ["atan2(y, 3 + x) + log(1 + z**2)", "abs(x - 10) + max(y, 3)*min(z, x - 5)"],
    ["10*(y - x)", "x*(28 - z) - y", "x*y - 8*z/3"],
]
"""Nonlinear maps of the language (the second is the engagement's ṙ, φ̇ form with v a parameter);
abs/min/max are used away from their kinks, where they are smooth."""


def central_difference(f, point: np.ndarray) -> np.ndarray:
    columns = []
    for j in range(point.size):
        e = np.zeros_like(point)
        e[j] = STEP
        columns.append((f(point + e) - f(point - e)) / (2 * STEP))
    return np.stack(columns, axis=-1)


coordinates = st.floats(-2.0, 2.0, allow_nan=False)


@settings(max_examples=40, deadline=None)
@given(index=st.integers(0, len(MAPS) - 1), point=st.tuples(coordinates, coordinates, coordinates))
def test_jacobian_matches_central_differences(index: int, point: tuple[float, float, float]) -> None:
    exprs = [parse(text, SYMBOLS) for text in MAPS[index]]
    values = {SYMBOLS["v"]: 1.3}
    exprs = [e.subs(values) for e in exprs]
    f = numeric_function(exprs, SYMS)
    J = numeric_function(jacobian(exprs, SYMS), SYMS)
    p = np.array(point)
    analytic = J(*p).reshape(len(exprs), len(SYMS))
    numeric = central_difference(lambda q: f(*q), p)
    np.testing.assert_allclose(analytic, numeric, rtol=TOL, atol=TOL)


def test_gradient_is_the_jacobian_row() -> None:
    expr = parse("x*y*cos(z) - sin(x)", SYMBOLS)
    assert gradient(expr, SYMS) == list(jacobian([expr], SYMS).row(0))


def test_numeric_function_broadcasts_and_refuses_unknown_symbols() -> None:
    x, y = SYMS[:2]
    f = numeric_function([x * y, sp.Integer(2), sp.sin(x)], [x, y])
    out = f(np.array([0.0, 1.0, 2.0]), 3.0)
    assert out.shape == (3, 3)
    np.testing.assert_array_equal(out[0], [0.0, 3.0, 6.0])
    np.testing.assert_array_equal(out[1], [2.0, 2.0, 2.0])
    np.testing.assert_array_equal(out[2], np.sin([0.0, 1.0, 2.0]))
    with pytest.raises(ExpressionError, match="z"):
        numeric_function([x + SYMS[2]], [x, y])


def test_linearize_matches_central_differences_along_a_trajectory() -> None:
    """A unicycle with drag and a time-varying wind, ẋ = f(x, u, t), along a trajectory: A(t) and
    B(t) at every grid point equal the central differences of f there (eq. 5.6)."""
    names = {"px": symbol("px"), "py": symbol("py"), "h": symbol("h"), "w": symbol("w"), "a": symbol("a")}
    k, t = symbol("k"), symbol("t")
    px, py, h, w, a = names.values()
    f = [sp.cos(h) * (1 + a) + k * sp.sin(t) - k * px**2, sp.sin(h) * (1 + a) - k * py * px, w * a]
    x, u = [px, py, h], [w, a]
    grid = np.linspace(0.0, 3.0, 25)
    states = np.column_stack([np.sin(grid), grid**2 / 4, np.cos(2 * grid)])
    controls = np.column_stack([1 + 0.5 * np.sin(grid), np.exp(-grid)])
    A, B = linearize(f, x, u, states, controls, {k: 0.3}, time=(t, grid))
    assert A.shape == (25, 3, 3) and B.shape == (25, 3, 2)
    value = numeric_function([e.subs(k, 0.3) for e in f], [*x, *u, t])
    for i, ti in enumerate(grid):
        z = np.concatenate([states[i], controls[i]])
        fd = central_difference(lambda q, ti=ti: value(*q, ti), z)
        np.testing.assert_allclose(A[i], fd[:, :3], rtol=TOL, atol=TOL)
        np.testing.assert_allclose(B[i], fd[:, 3:], rtol=TOL, atol=TOL)
