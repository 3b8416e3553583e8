"""The CasADi backend's three NLP constructions are one NLP: the assembled derivatives (per-point
Jacobians and Hessians summed with constant matrices, the default) equal CasADi's own AD of the
closed NLP at random points, and every graph (``assembled``, flat ``sx``, ``mx``) reaches the
closed-form optimum of Zermelo's max-range problem (the linear tangent law) on a first solve and on
a re-solve with a new parameter, and the same optimum (objective and trajectory) elsewhere."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
from gamespec_casadi.assembly import assembled_nlp
from gamespec_casadi.nlp import collocation_nlp

import gamespec
from gamespec.loader import spec_from_dict
from gamespec.ocp.transcription import Transcription
from gamespec.solving import get_backend
from gamespec.symbolic.library import casadi_library
from tests.conftest import PROBLEMS
from tests.core.test_ocp_modelling import (
    _bounded_in_time,
    _design_problem,
    _double_integrator,
    _isoperimetric,
)
from tests.core.test_ocp_theory import _zermelo_closed_form

GRAPHS = ("assembled", "sx", "mx")
ZERMELO_RANGE = PROBLEMS / "ch6" / "zermelo_max_range.yaml"


def _with_path_and_penalty() -> dict:
    """The double integrator with a path constraint, a boundary constraint on the end controls, a
    parameter in the dynamics, a free final time and a control-rate penalty: every term the NLP
    has."""
    data = _double_integrator(["u_0 <= 5"])
    data["problem"]["parameters"] = {"k": 1.5}
    data["problem"]["dynamics"]["v"] = "k*u"
    data["problem"]["path_constraints"] = ["v <= 1.6"]
    data["problem"]["objective"]["lagrange"] = "u**2/2 + 1"
    data["problem"]["time"] = {"final": "free", "bounds": [0.5, 3.0], "guess": 1.0}
    data["method"]["control_rate_penalty"] = 1e-3
    return data


CASES = {
    "cart_pole": lambda: gamespec.load(PROBLEMS / "ocp" / "cart_pole_swing_up.yaml"),
    "zermelo_min_time": lambda: gamespec.load(PROBLEMS / "ch6" / "zermelo_min_time.yaml"),
    "zermelo_trapezoidal": lambda: gamespec.load(ZERMELO_RANGE, ["method.scheme=trapezoidal"]),
    "zermelo_degrees_per_interval": lambda: gamespec.load(
        ZERMELO_RANGE, ["method.intervals=4", "method.degrees=[2, 5, 3, 1]"]
    ),
    "design_variable": lambda: spec_from_dict(_design_problem(False, "casadi")),
    "integral_constraint": lambda: spec_from_dict(_isoperimetric(False, "casadi")),
    "linear_with_path_constraint": lambda: spec_from_dict(_bounded_in_time(False)),
    "path_and_penalty": lambda: spec_from_dict(_with_path_and_penalty()),
}


def _dense(value) -> np.ndarray:
    return np.array(ca.densify(value))


@pytest.mark.parametrize("case", sorted(CASES))
def test_assembled_derivatives_are_the_derivatives_of_the_nlp(case: str) -> None:
    """Jacobian, gradient and (upper triangle of the) Lagrangian Hessian against CasADi's AD of the
    same NLP with the point function mapped in place, at a random point: the same sums in another
    order, so equal to rounding."""
    tr = Transcription(CASES[case]())
    sx, su = tr.scales(tr.ocp.parameter_values())
    nlp = collocation_nlp(tr, casadi_library(ca), ca.MX, sx, su)
    assembled = assembled_nlp(nlp).derivatives
    closed = nlp.closed()
    x, p, f, g = closed["x"], closed["p"], closed["f"], closed["g"]
    sigma, lam = ca.MX.sym("sigma"), ca.MX.sym("lam", g.numel())
    reference = ca.Function(
        "reference",
        [x, p, sigma, lam],
        [f, ca.gradient(f, x), g, ca.jacobian(g, x), ca.triu(ca.hessian(sigma * f + ca.dot(lam, g), x)[0])],
    )
    rng = np.random.default_rng(7)
    point = [
        rng.uniform(0.5, 1.5, x.numel()),
        rng.uniform(0.5, 1.5, p.numel()),
        0.7,
        rng.normal(size=g.numel()),
    ]
    f_ref, grad_ref, g_ref, jac_ref, hess_ref = (_dense(v) for v in reference(*point))
    f_val, grad_val = (_dense(v) for v in assembled["grad_f"](*point[:2]))
    g_val, jac_val = (_dense(v) for v in assembled["jac_g"](*point[:2]))
    hess_val = _dense(assembled["hess_lag"](*point))
    for value, ref in (
        (f_val, f_ref),
        (grad_val, grad_ref),
        (g_val, g_ref),
        (jac_val, jac_ref),
        (hess_val, hess_ref),
    ):
        assert value.shape == ref.shape
        assert np.max(np.abs(value - ref)) <= 1e-11 * max(1.0, np.max(np.abs(ref)))


def _models(spec_of) -> dict:
    return {graph: get_backend("casadi").compile(spec_of(graph)) for graph in GRAPHS}


def _agree(results: dict) -> None:
    """Every graph's optimum equals the assembled one: the objective to 1e-8 relative, the
    trajectory to the solver's tolerance."""
    base = results["assembled"]
    for graph, result in results.items():
        assert result.ok, graph
        assert result.objective == pytest.approx(base.objective, rel=1e-8), graph
        for group in ("states", "controls"):
            for name, values in getattr(base, group).items():
                assert np.max(np.abs(getattr(result, group)[name] - values)) < 1e-6, (graph, name)


def test_every_graph_reaches_the_linear_tangent_law_and_again_after_a_new_parameter() -> None:
    models = _models(lambda graph: gamespec.load(ZERMELO_RANGE, [f"solver.options.casadi.graph={graph}"]))
    for rho in (10.0, 6.0):
        results = {graph: model.solve(parameters={"rho": rho}) for graph, model in models.items()}
        x1f, heading = _zermelo_closed_form(rho)
        for result in results.values():
            assert result.objective == pytest.approx(x1f, rel=1e-6)
            assert np.max(np.abs(result.controls["u"] - heading(result.control_time))) < 1e-5
        _agree(results)


@pytest.mark.parametrize("case", ["cart_pole", "zermelo_min_time", "path_and_penalty"])
def test_every_graph_reaches_the_same_optimum(case: str) -> None:
    def spec_of(graph: str):
        spec = CASES[case]()
        options = spec.solver.options | {"casadi": {"graph": graph}}
        return spec.model_copy(update={"solver": spec.solver.model_copy(update={"options": options})})

    models = _models(spec_of)
    _agree({graph: model.solve() for graph, model in models.items()})
