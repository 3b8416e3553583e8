"""Optimal-control modelling constructs (issue 17) against what they replace: definitions against
the expressions written out, derived parameters against the number they evaluate to."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
import sympy as sp

import gamespec
from gamespec.compiling.refinement import refined_mesh
from gamespec.errors import ExpressionError, SpecError
from gamespec.loader import spec_from_dict
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.ocp.transcription import Transcription
from gamespec.solving import get_backend
from gamespec.specs.ocp import RefineSpec
from gamespec.symbolic.language import parse
from tests.conftest import PROBLEMS

HANG_GLIDER = PROBLEMS / "ocp" / "hang_glider.yaml"
SMALL = ["method.intervals=10"]


def test_definitions_are_substituted_into_the_dynamics() -> None:
    ocp = SymbolicOcp(gamespec.load(HANG_GLIDER))
    x, vx, vy, cL = sp.symbols("x vx vy cL", real=True)
    uc, r0, m, c0, c1, q = sp.symbols("uc r0 m c0 c1 q", real=True)
    r = (x / r0 - 2.5) ** 2
    w = vy - uc * (1 - r) * sp.exp(-r)
    v = sp.sqrt(vx**2 + w**2)
    drag, lift = q * (c0 + c1 * cL**2) * v**2, q * cL * v**2
    gap = ocp.dynamics[2] - (-lift * w / v - drag * vx / v) / m
    point = {x: 310.0, vx: 12.0, vy: -1.1, cL: 0.9, uc: 2.5, r0: 100.0, m: 100.0, c0: 0.03, c1: 0.07, q: 7.9}
    assert abs(float(gap.subs(point))) < 1e-12
    assert not set(ocp.dynamics[3].free_symbols) & {sp.Symbol(n, real=True) for n in ("w", "v", "lift")}


def test_a_derived_parameter_follows_the_parameters_it_uses() -> None:
    spec = gamespec.load(HANG_GLIDER, SMALL)
    solver = gamespec.compile_spec(spec)
    moved = solver.solve(parameters={"S": 15.0})
    assert moved.ok
    assert SymbolicOcp(spec).parameter_values({"S": 15.0})["q"] == pytest.approx(0.5 * 1.13 * 15.0)
    fixed = gamespec.solve(gamespec.load(HANG_GLIDER, [*SMALL, "problem.parameters.S=15.0"]))
    assert moved.objective == pytest.approx(fixed.objective, rel=1e-8)
    assert "q" not in spec.runtime_parameters()


def test_a_derived_parameter_is_not_set_on_its_own() -> None:
    spec = gamespec.load(HANG_GLIDER, SMALL)
    with pytest.raises(SpecError, match="derived"):
        SymbolicOcp(spec).parameter_values({"q": 1.0})


def test_a_derived_parameter_may_only_use_earlier_ones() -> None:
    with pytest.raises(SpecError, match="undefined symbol 'rho'"):
        gamespec.load(HANG_GLIDER, ["problem.parameters.uc=0.5*rho"])


def _design_problem(workaround: bool, backend: str) -> dict:
    """min integral(u**2) + (a - 1)**2 with x' = u, x(0) = 0, x(1) = a: J(a) = a**2 + (a - 1)**2,
    so a = 1/2 and J = 1/2; ``a`` a design variable, or a constant state with a free start."""
    problem: dict = {
        "states": {"x": {"initial": 0.0}},
        "controls": {"u": {}},
        "dynamics": {"x": "u"},
        "objective": {"lagrange": "u**2"},
    }
    if workaround:
        problem["states"]["a"] = {"lower": -5.0, "upper": 5.0}
        problem["dynamics"]["a"] = "0"
        problem["objective"]["mayer"] = "(a_0 - 1)**2"
        problem["boundary_constraints"] = ["x_f == a_f"]
    else:
        problem["design"] = {"a": {"lower": -5.0, "upper": 5.0, "guess": 2.0}}
        problem["objective"]["mayer"] = "(a - 1)**2"
        problem["boundary_constraints"] = ["x_f == a"]
    return {
        "kind": "optimal_control",
        "problem": problem,
        "method": {"intervals": 8},
        "solver": {"backend": backend},
    }


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_a_design_variable_matches_the_constant_state_workaround(backend: str) -> None:
    design = gamespec.solve(spec_from_dict(_design_problem(False, backend)))
    constant = gamespec.solve(spec_from_dict(_design_problem(True, backend)))
    assert design.status == constant.status == gamespec.Status.OPTIMAL
    assert design.metrics["design"]["a"] == pytest.approx(0.5, abs=1e-7)
    assert design.metrics["design"]["a"] == pytest.approx(constant.states["a"][0], abs=1e-7)
    assert design.objective == pytest.approx(0.5, abs=1e-7)
    assert design.objective == pytest.approx(constant.objective, abs=1e-7)
    assert design.checks["max_constraint_violation"] < 1e-7


def _isoperimetric(quadrature_state: bool, backend: str) -> dict:
    """min integral(u**2), x' = u, x(0) = 0, x(1) = 1, integral(x) = 1/3: the multiplier makes x
    quadratic, x = t**2, so J = 4/3 (and the degree-3 collocation is exact)."""
    problem: dict = {
        "states": {"x": {"initial": 0.0, "final": 1.0}},
        "controls": {"u": {}},
        "dynamics": {"x": "u"},
        "objective": {"lagrange": "u**2"},
    }
    if quadrature_state:
        problem["states"]["area"] = {"initial": 0.0, "final": 1 / 3}
        problem["dynamics"]["area"] = "x"
    else:
        problem["integral_constraints"] = [{"integrand": "x", "lower": 1 / 3, "upper": 1 / 3}]
    return {
        "kind": "optimal_control",
        "problem": problem,
        "method": {"intervals": 6},
        "solver": {"backend": backend},
    }


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_an_integral_constraint_matches_a_quadrature_state(backend: str) -> None:
    integral = gamespec.solve(spec_from_dict(_isoperimetric(False, backend)))
    state = gamespec.solve(spec_from_dict(_isoperimetric(True, backend)))
    assert integral.status == state.status == gamespec.Status.OPTIMAL
    assert integral.objective == pytest.approx(4 / 3, abs=1e-8)
    assert integral.objective == pytest.approx(state.objective, abs=1e-8)
    assert np.allclose(integral.states["x"], integral.time**2, atol=1e-7)
    assert integral.checks["max_constraint_violation"] < 1e-8


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_an_integral_bound_over_the_parameters_follows_them_on_a_re_solve(backend: str) -> None:
    """integral(x) = A with x(0) = 0, x(1) = 1: x = a t^2 + b t with a = 3 - 6A, b = 1 - a, and
    J = integral((2at + b)^2) = 4a^2/3 + 2ab + b^2 (4/3 at A = 1/3, 1.12 at A = 0.4)."""
    data = _isoperimetric(False, backend)
    data["problem"]["parameters"] = {"A": 1 / 3}
    data["problem"]["integral_constraints"] = [{"integrand": "x", "lower": "A", "upper": "A"}]
    solver = gamespec.compile_spec(spec_from_dict(data))
    for area in (1 / 3, 0.4):
        a = 3 - 6 * area
        b = 1 - a
        result = solver.solve(parameters={"A": area})
        assert result.status == gamespec.Status.OPTIMAL
        assert result.objective == pytest.approx(4 * a * a / 3 + 2 * a * b + b * b, abs=1e-8)
        assert result.checks["max_constraint_violation"] < 1e-8


def test_an_integral_bound_over_what_is_not_a_parameter_is_refused() -> None:
    data = _isoperimetric(False, "casadi")
    data["problem"]["integral_constraints"] = [{"integrand": "x", "upper": "x_f"}]
    with pytest.raises(SpecError, match="undefined symbol 'x_f'") as err:
        spec_from_dict(data)
    assert err.value.field == "problem.integral_constraints.0.upper"


def _bounded_in_time(as_bound: bool) -> dict:
    """max x(1), x' = u, with u <= 1 - t: x(1) = 1/2 (the bound is active throughout)."""
    controls = {"u": {"lower": -1.0, "upper": "1 - t"}} if as_bound else {"u": {"lower": -1.0}}
    problem = {
        "states": {"x": {"initial": 0.0}},
        "controls": controls,
        "dynamics": {"x": "u"},
        "objective": {"sense": "maximize", "mayer": "x_f"},
        "path_constraints": [] if as_bound else ["u <= 1 - t"],
    }
    return {"kind": "optimal_control", "problem": problem, "method": {"intervals": 5}}


def test_a_bound_over_time_is_the_path_constraint() -> None:
    bound = gamespec.solve(spec_from_dict(_bounded_in_time(True)))
    path = gamespec.solve(spec_from_dict(_bounded_in_time(False)))
    # An active inequality: the interior point stops ~ (points x tol) inside it.
    assert bound.objective == pytest.approx(0.5, abs=1e-6)
    assert bound.objective == pytest.approx(path.objective, abs=1e-10)
    assert np.allclose(bound.controls["u"], 1 - bound.control_time, atol=1e-6)


def test_a_bound_over_a_state_points_to_path_constraints() -> None:
    data = _bounded_in_time(True)
    data["problem"]["controls"]["u"]["upper"] = "1 - x"
    with pytest.raises(SpecError, match="path_constraints") as err:
        spec_from_dict(data)
    assert err.value.field == "problem.controls.u.upper"


def _double_integrator(boundary: list[str], backend: str = "casadi") -> dict:
    """Minimum energy rest-to-rest, x'' = u on [0, 1] from 0 to 1: u = 6 - 12 t, so u_0 = 6, u_f = -6."""
    problem = {
        "states": {"x": {"initial": 0.0, "final": 1.0}, "v": {"initial": 0.0, "final": 0.0}},
        "controls": {"u": {}},
        "dynamics": {"x": "v", "v": "u"},
        "objective": {"lagrange": "u**2/2"},
        "boundary_constraints": boundary,
    }
    return {
        "kind": "optimal_control",
        "problem": problem,
        "method": {"intervals": 4},
        "solver": {"backend": backend},
    }


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_controls_at_the_end_points(backend: str) -> None:
    free = gamespec.solve(spec_from_dict(_double_integrator([], backend)))
    inactive = gamespec.solve(spec_from_dict(_double_integrator(["u_0 >= 5.99", "u_f <= -5.99"], backend)))
    assert inactive.objective == pytest.approx(free.objective, abs=1e-7)
    assert inactive.objective == pytest.approx(6.0, abs=1e-7)
    moved = gamespec.solve(spec_from_dict(_double_integrator(["u_0 == 7"], backend)))
    tr = Transcription(spec_from_dict(_double_integrator([])))
    first, _ = tr.end_controls(np.atleast_2d(moved.controls["u"]))
    assert first[0] == pytest.approx(7.0, abs=1e-7)
    assert moved.checks["max_constraint_violation"] < 1e-7
    free_first, free_last = tr.end_controls(np.atleast_2d(free.controls["u"]))
    assert (free_first[0], free_last[0]) == pytest.approx((6.0, -6.0), abs=1e-6)


def test_one_spelling_of_nlp_options_reaches_both_backends() -> None:
    spec = gamespec.load(
        HANG_GLIDER,
        [
            "solver.options.nlp.tol=1e-7",
            "solver.options.nlp.mu_strategy=adaptive",
            "solver.options.pyomo.tol=1e-6",
        ],
    )
    casadi = get_backend("casadi").options(spec)
    pyomo = get_backend("pyomo").options(spec)
    assert casadi.tol == 1e-7 and casadi.ipopt == {"mu_strategy": "adaptive"}
    assert pyomo.tol == 1e-6 and pyomo.options == {"mu_strategy": "adaptive"}
    assert casadi.max_wall_time == pyomo.max_wall_time > 0


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_the_wall_time_limit_stops_a_solve(backend: str) -> None:
    spec = gamespec.load(HANG_GLIDER, ["solver.options.nlp.max_wall_time=1e-4", f"solver.backend={backend}"])
    assert gamespec.solve(spec).status == gamespec.Status.TIME_LIMIT


@pytest.mark.parametrize("group", ["states", "controls", "parameters"])
def test_tau_is_refused_as_a_name_with_the_reason(group: str) -> None:
    data = _isoperimetric(False, "casadi")
    problem = data["problem"]
    if group == "states":
        problem["states"]["tau"] = {"initial": 0.0}
        problem["dynamics"]["tau"] = "1"
    elif group == "controls":
        problem["controls"]["tau"] = {}
    else:
        problem["parameters"] = {"tau": 1.0}
    with pytest.raises(SpecError, match=r"'tau' cannot be a symbol name.*normalized time"):
        spec_from_dict(data)


def test_a_caret_in_a_file_names_the_field_and_the_column_of_the_caret() -> None:
    data = _isoperimetric(False, "casadi")
    data["problem"]["objective"]["lagrange"] = "u^2"
    with pytest.raises(SpecError, match=r"at column 2: '\^' is not a power: use \*\* for powers") as err:
        spec_from_dict(data)
    assert err.value.field == "problem.objective.lagrange"


def test_a_caret_says_to_use_double_star_at_its_column() -> None:
    with pytest.raises(ExpressionError, match=r"use \*\* for powers") as err:
        parse("1 + v^2", {"v": sp.Symbol("v", real=True)})
    assert err.value.column == 5


def test_a_linear_guess_with_one_free_end_heads_for_the_middle_of_the_bounds() -> None:
    data = _bounded_in_time(False)
    data["problem"]["states"] = {
        "x": {"initial": 0.0, "lower": -2.0, "upper": 4.0},
        "z": {"final": 3.0},
    }
    data["problem"]["dynamics"] = {"x": "u", "z": "u"}
    data["problem"]["objective"]["mayer"] = "x_f"
    tr = Transcription(spec_from_dict(data))
    start = tr.guess(tr.ocp.parameter_values())
    assert start.X[0, 0] == 0.0 and start.X[0, -1] == pytest.approx(1.0)
    assert np.all(start.X[1] == 3.0)


GODDARD = PROBLEMS / "ocp" / "goddard_rocket.yaml"


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_the_chattering_check_fires_on_goddard_and_a_rate_penalty_removes_it(backend: str) -> None:
    """Goddard's thrust is bang-singular-off (monotone: one sweep of its range); the collocated
    singular arc chatters without regularization. The penalty perturbs h_f by O(w)."""
    raw = gamespec.solve(GODDARD, backend)
    smooth = gamespec.solve(gamespec.load(GODDARD, ["method.control_rate_penalty=1.0e-6"]), backend)
    assert raw.checks["chattering"] == 1.0 and raw.checks["control_swings/T"] > 10
    assert smooth.checks["chattering"] == 0.0 and smooth.checks["control_swings/T"] < 1.5
    assert smooth.objective == pytest.approx(smooth.states["h"][-1], abs=1e-12)
    assert smooth.objective == pytest.approx(raw.objective, rel=1e-4)


@pytest.mark.parametrize("strategy", ["h", "hp"])
@pytest.mark.parametrize("backend", ["casadi", pytest.param("pyomo", marks=pytest.mark.slow)])
def test_mesh_refinement_reaches_its_tolerance_on_the_hang_glider(backend: str, strategy: str) -> None:
    tolerance = 1e-6
    overrides = ["method.intervals=10", f"method.refine.tolerance={tolerance}"]
    spec = gamespec.load(HANG_GLIDER, [*overrides, f"method.refine.strategy={strategy}"])
    result = gamespec.solve(spec, backend)
    history = result.metrics["refinement"]
    defects = [entry["max_defect_relative"] for entry in history]
    assert result.status == gamespec.Status.OPTIMAL and result.metrics["refinement_converged"]
    assert result.checks["max_defect_relative"] <= tolerance
    assert all(later < earlier for earlier, later in itertools.pairwise(defects))
    assert all(later["variables"] > earlier["variables"] for earlier, later in itertools.pairwise(history))
    assert max(e["max_degree"] for e in history) <= (3 if strategy == "h" else spec.method.refine.max_degree)
    # Betts' x_f (the file's reference); the interval gaps, each below the tolerance relative to the
    # state's scale, add up to at most intervals * tolerance of it at the end.
    assert result.objective == pytest.approx(1248.03103, rel=history[-1]["intervals"] * tolerance)


def test_hp_refinement_raises_the_degree_where_the_rule_predicts_the_tolerance() -> None:
    """The ph rule: an interval of N points with defect e needs P = ceil(log(e/tol)/log N) more;
    within max_degree it gets them, beyond it is split into intervals of the file's degree."""
    options = RefineSpec(tolerance=1e-6, strategy="hp", max_degree=10)
    breaks = np.array([0.0, 0.25, 0.5, 1.0])
    mesh, degrees = refined_mesh(breaks, np.array([3, 3, 3]), np.array([1e-7, 1e-3, 1e-1]), options, 3)
    assert degrees[:2] == [3, 3 + math.ceil(math.log(1e3) / math.log(3))]
    wanted = 3 + math.ceil(math.log(1e5) / math.log(3))
    assert degrees[2:] == [3] * math.ceil(wanted / 3)
    assert mesh[:3] == [0.0, 0.25, 0.5] and np.allclose(np.diff(mesh[2:]), 0.5 / len(degrees[2:]))


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_a_mesh_of_mixed_degrees_is_exact_on_a_quadratic_solution(backend: str) -> None:
    """The isoperimetric problem's x = t^2 is a polynomial of degree 2: every interval of degree
    >= 2 collocates it exactly, whatever its neighbours' degrees."""
    data = _isoperimetric(False, backend)
    data["method"] = {"intervals": 4, "degrees": [2, 5, 3, 4]}
    result = gamespec.solve(spec_from_dict(data))
    assert result.status == gamespec.Status.OPTIMAL
    assert result.objective == pytest.approx(4 / 3, abs=1e-8)
    assert np.allclose(result.states["x"], result.time**2, atol=1e-8)
    assert result.checks["max_defect"] < 1e-10


def test_each_check_has_a_verdict_against_its_tolerance() -> None:
    coarse = gamespec.solve(gamespec.load(HANG_GLIDER, SMALL))
    passed = coarse.metrics["checks_passed"]
    assert passed["max_constraint_violation"] is (coarse.checks["max_constraint_violation"] <= 1e-6)
    assert passed["max_defect_relative"] is False  # 10 intervals: a relative defect of order 1e-1
    assert coarse.checks["max_defect_relative"] <= coarse.checks["max_defect"]  # scales are >= 1


def test_scale_factors_from_the_file_the_bounds_and_the_guess() -> None:
    tr = Transcription(gamespec.load(HANG_GLIDER))
    sx, su = tr.scales(tr.ocp.parameter_values())
    # given; auto from the guess (1000 -> 900: 10^3); unset, so auto, of magnitude ~10: 1
    assert list(sx) == [1000.0, 1000.0, 1.0, 1.0]
    assert list(su) == [1.0]  # auto from the guess 0.7 (the middle of [0, 1.4]): within 10^±2 of 1


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_scaling_leaves_the_optimum_where_it_is(backend: str) -> None:
    unscaled = [
        "problem.states.x.scale=none",
        "problem.states.y.scale=none",
        "problem.controls.cL.scale=none",
        "method.scale=none",
    ]
    scaled = gamespec.solve(gamespec.load(HANG_GLIDER, SMALL), backend)
    plain = gamespec.solve(gamespec.load(HANG_GLIDER, [*SMALL, *unscaled]), backend)
    # 10 intervals: the solver converges, the relative defect (of order 1e-1) fails, so both are
    # feasible for that reason alone (the status policy)
    assert scaled.status == plain.status == gamespec.Status.FEASIBLE
    assert [f.name for f in scaled.failed_checks()] == [f.name for f in plain.failed_checks()]
    assert [f.name for f in scaled.failed_checks()] == ["max_defect_relative"]
    assert scaled.objective == pytest.approx(plain.objective, rel=1e-8)
    assert np.allclose(scaled.states["x"], plain.states["x"], rtol=1e-6, atol=1e-6)
