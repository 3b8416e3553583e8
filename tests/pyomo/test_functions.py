"""Every function of the expression language through Pyomo's NL file and the NL solver against
CasADi's own evaluation and derivatives: a small OCP per function, whose optimum moves with the
function's value and gradient, must come out the same on both backends."""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.result import Status

TERMS = {
    "sin": "sin(x + u)",
    "cos": "cos(x*u)",
    "tan": "tan(0.5*u)",
    "asin": "asin(0.5*x)",
    "acos": "acos(0.5*u)",
    "atan": "atan(x - u)",
    "exp": "exp(u)",
    "log": "log(2 + x)",
    "sqrt": "sqrt(2 + u)",
    "abs": "abs(u + 1)*x",
    "tanh": "tanh(x + u)",
    "min": "min(u, x + 2)",
    "max": "max(x*u, -2)",
    "power": "x**3 + 2**u + (2 + u)**1.5",
    "division": "x / (2 + u)",
}
"""One term per function; |u| <= 0.5 and x in [-0.3, 0.7] keep each on a smooth piece of its
domain."""


def _spec(term: str):
    return gamespec.spec_from_dict(
        {
            "kind": "optimal_control",
            "name": "function_check",
            "problem": {
                "states": {"x": {"initial": 0.2}},
                "controls": {"u": {"lower": -0.5, "upper": 0.5}},
                "dynamics": {"x": "u"},
                "objective": {"lagrange": f"(u - 0.3)**2 + 0.5*({term})", "mayer": "(x_f - 0.5)**2"},
                "time": {"final": 1.0},
            },
            "method": {"intervals": 8, "degree": 3},
        }
    )


@pytest.mark.parametrize("name", sorted(TERMS))
def test_function_agrees_across_backends(name: str) -> None:
    spec = _spec(TERMS[name])
    casadi, pyomo = gamespec.solve(spec, "casadi"), gamespec.solve(spec, "pyomo")
    assert casadi.status is Status.OPTIMAL and pyomo.status is Status.OPTIMAL, pyomo.message
    assert pyomo.objective == pytest.approx(casadi.objective, rel=1e-8, abs=1e-10)
    np.testing.assert_allclose(pyomo.controls["u"], casadi.controls["u"], atol=1e-6)
