"""Eq. 6.33: every relevance function is non-decreasing on (-inf, 0] and constant for w > 0."""

import numpy as np
import pytest
import sympy as sp

from gamespec.errors import ExpressionError
from gamespec.rcs.relevance import NAMED, W, profile, relevance
from gamespec.symbolic.calculus import numeric_function

NEGATIVE = np.linspace(-30.0, 0.0, 3001)
POSITIVE = np.linspace(1e-6, 30.0, 301)


def values(choice, w):
    g = sp.Symbol("g")
    return np.broadcast_to(numeric_function([relevance(choice, g)], [g])(w), (1, w.size))[0]


@pytest.mark.parametrize("choice", [*NAMED, "1/(1 + w**4)"])
def test_monotone_then_constant(choice):
    below, above = values(choice, NEGATIVE), values(choice, POSITIVE)
    assert np.all(below >= 0)
    assert np.all(np.diff(below) >= -1e-15)
    r0 = float(sp.sympify(profile(choice)).subs(W, 0))
    np.testing.assert_allclose(above, r0, rtol=1e-14, atol=0)
    assert below[-1] == pytest.approx(r0)


def test_logistic_derivative_peaks_at_a_quarter():
    assert values("logistic_derivative", np.array([0.0]))[0] == pytest.approx(0.25)


@pytest.mark.parametrize("bad", ["-w", "exp(w**2)", "w"])
def test_expressions_that_break_eq_6_33_are_refused(bad):
    with pytest.raises(ExpressionError):
        profile(bad)


def test_built_from_min_only():
    """No sign/heaviside (pyomo refuses them): r is r̃(min(g, 0))."""
    g = sp.Symbol("g")
    for choice in NAMED:
        expr = relevance(choice, g)
        assert not expr.has(sp.sign, sp.Heaviside)
        assert expr.has(sp.Min)


def test_logistic_forms_equal_eq_6_35():
    w = np.linspace(-20.0, 0.0, 201)
    s = 1 / (1 + np.exp(-w))
    np.testing.assert_allclose(values("logistic_derivative", w), s * (1 - s), rtol=1e-12)
    np.testing.assert_allclose(values("logistic", w), s, rtol=1e-12)
