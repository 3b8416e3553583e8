"""The PYOMO library of the one SymPy translator: a Pyomo expression evaluates to what the NUMPY
translation of the same SymPy tree gives (two translations of one form agreeing)."""

from __future__ import annotations

import math

import pyomo.environ as pyo
import pytest
from gamespec_pyomo.model import pyomo_library
from hypothesis import given, settings
from hypothesis import strategies as st

from gamespec.symbolic.language import parse, symbol
from gamespec.symbolic.library import NUMPY
from gamespec.symbolic.translate import translate

EXPRESSIONS = [
    "sin(x)*cos(y) - tan(x/4)",
    "asin(x/10) + acos(y/10) + atan(x*y)",
    "exp(-x**2) + log(1 + y**2) + sqrt(1 + x**2)",
    "abs(x - y) + tanh(x)",
    "min(x, y) - max(x, max(y, 0.5)) + min(x, min(2*y, -y))",
    "x**3 / (1 + y**2) - 2**y",
]
SYMBOLS = {"x": symbol("x"), "y": symbol("y")}
finite = st.floats(-5.0, 5.0, allow_nan=False)


@pytest.fixture(scope="module")
def model():
    m = pyo.ConcreteModel()
    m.x = pyo.Var()
    m.y = pyo.Var()
    lib = pyomo_library()
    values = {SYMBOLS["x"]: m.x, SYMBOLS["y"]: m.y}
    m.exprs = [translate(parse(text, SYMBOLS), values, lib) for text in EXPRESSIONS]
    return m


@settings(max_examples=50, deadline=None)
@given(x=finite, y=finite)
def test_pyomo_and_numpy_translations_agree(model, x: float, y: float) -> None:
    model.x.set_value(x)
    model.y.set_value(y)
    for text, expr in zip(EXPRESSIONS, model.exprs, strict=True):
        expected = float(translate(parse(text, SYMBOLS), {SYMBOLS["x"]: x, SYMBOLS["y"]: y}, NUMPY))
        assert math.isfinite(expected)
        assert pyo.value(expr) == pytest.approx(expected, rel=1e-12, abs=1e-12), text
