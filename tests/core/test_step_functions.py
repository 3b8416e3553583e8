"""``sign`` and ``heaviside`` mean the same on every backend as in SymPy (``sign(0) = 0``,
``heaviside(0) = 1/2``), and the pyomo backend, which cannot express them, refuses them by name."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pyomo.environ as pyo
import pytest
import sympy as sp
from gamespec_pyomo.model import pyomo_library

from gamespec.errors import UnsupportedFeature
from gamespec.symbolic.language import parse, symbol
from gamespec.symbolic.library import NUMPY, casadi_library
from gamespec.symbolic.translate import translate

X = symbol("x")
EXPRESSIONS = ["sign(x)", "heaviside(x)", "sign(x - 1)*heaviside(1 - x) + heaviside(x)**2"]
POINTS = [-2.0, -1e-300, 0.0, 1e-300, 1.0, 3.0]


@pytest.mark.parametrize("text", EXPRESSIONS)
def test_numpy_and_casadi_take_sympy_values_at_and_off_the_jumps(text: str) -> None:
    expr = parse(text, {"x": X})
    x = ca.SX.sym("x")
    on_casadi = ca.Function("f", [x], [translate(expr, {X: x}, casadi_library(ca))])
    on_numpy = translate(expr, {X: np.array(POINTS)}, NUMPY)
    for point, numpy_value in zip(POINTS, on_numpy, strict=True):
        exact = float(expr.subs(X, sp.Float(point)))
        assert numpy_value == exact, (text, point)
        assert float(on_casadi(point)) == exact, (text, point)


@pytest.mark.parametrize(("text", "name"), [("1 + sign(x)", "sign"), ("x*heaviside(x - 1)", "heaviside")])
def test_pyomo_refuses_step_functions_by_name(text: str, name: str) -> None:
    m = pyo.ConcreteModel()
    m.x = pyo.Var()
    with pytest.raises(UnsupportedFeature, match=f"cannot take {name}"):
        translate(parse(text, {"x": X}), {X: m.x}, pyomo_library())
