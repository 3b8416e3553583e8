"""Grid inputs (issue 9, item 5): signals tabulated at the evaluation points of the transcription,
re-solved on one compiled model without a rebuild, on casadi and pyomo.

The test problem: x' = u + w(t), x(0) = 0, x(T) = x_f, minimize the integral of u^2. With
H = u^2 + lambda (u + w), lambda' = -dH/dx = 0, so lambda is constant and u = -lambda/2 is constant
(eq. 2.22 in this form); integrating the dynamics, x_f = u T + int_0^T w dt, so

    u* = (x_f - int_0^T w dt) / T,    J* = T u*^2,

whatever the signal w. On the transcription the same holds with the integral replaced by the
Radau quadrature of the tabulated w (the end-of-interval rows of the collocation are
x_end - x_start = h sum_j b_j (u_j + w_j)), which is exact to degree 2d - 2 per interval: for the smooth
signals below the gap to the continuous integral is far below the solver tolerance.
"""

from __future__ import annotations

import math

import casadi
import numpy as np
import pytest
from gamespec_pyomo import backend as pyomo_backend

import gamespec
from gamespec.errors import SpecError
from gamespec.loader import spec_from_dict
from gamespec.ocp.transcription import Transcription
from gamespec.result import Result
from tests.conftest import PROBLEMS

BACKENDS = ("casadi", "pyomo")
A, T, XF = 0.5, 2.0, 1.0
SIGNALS = {
    "a*sin(pi*tau)": ("a*sin(pi*tau)", 2.0 * A * T / math.pi),
    "cos(t)": ("cos(T*tau)", math.sin(T)),
    "0.3*t**2": ("0.3*(T*tau)**2", 0.1 * T**3),
}
"""Each signal: its default expression (of tau and the parameters) and its integral over [0, T]."""

SOLVER_TOL = 1e-6
"""Agreement asked of two IPOPT solves at tol 1e-8 on this well-conditioned QP (u is O(1))."""


def _data(default: str = "a*sin(pi*tau)", **problem) -> dict:
    return {
        "kind": "optimal_control",
        "name": "drift",
        "problem": {
            "parameters": {"a": A, "T": T},
            "states": {"x": {"initial": 0.0, "final": XF}},
            "controls": {"u": {}},
            "inputs": {"w": {"default": default}},
            "dynamics": {"x": "u + w"},
            "objective": {"lagrange": "u**2"},
            "time": {"final": "T"},
        }
        | problem,
        "method": {"scheme": "radau", "intervals": 10, "degree": 3},
    }


def _optimum(integral: float) -> float:
    return (XF - integral) / T


def _assert_optimal(result: Result, integral: float) -> None:
    assert result.status == gamespec.Status.OPTIMAL, result.message
    u = _optimum(integral)
    np.testing.assert_allclose(result.controls["u"], u, atol=SOLVER_TOL)
    assert result.objective == pytest.approx(T * u**2, abs=SOLVER_TOL)


@pytest.fixture
def builds(monkeypatch) -> dict[str, int]:
    """How often each backend built its model (CasADi's nlpsol, the Pyomo model)."""
    counts = dict.fromkeys(BACKENDS, 0)

    def counting(name, real):
        def build(*args, **kwargs):
            counts[name] += 1
            return real(*args, **kwargs)

        return build

    monkeypatch.setattr(casadi, "nlpsol", counting("casadi", casadi.nlpsol))
    monkeypatch.setattr(pyomo_backend, "build_model", counting("pyomo", pyomo_backend.build_model))
    return counts


@pytest.mark.parametrize("backend", BACKENDS)
def test_resolve_with_new_inputs_equals_a_fresh_build(backend: str, builds: dict[str, int]) -> None:
    solver = gamespec.compile_spec(spec_from_dict(_data()), backend)
    grid = solver.compiled.input_grid()
    np.testing.assert_allclose(grid.time, T * grid.tau)
    _assert_optimal(solver.solve(), SIGNALS["a*sin(pi*tau)"][1])
    resolved = {}
    for name in ("cos(t)", "0.3*t**2"):
        values = np.cos(grid.time) if name == "cos(t)" else 0.3 * grid.time**2
        resolved[name] = solver.solve(inputs={"w": values})
        np.testing.assert_array_equal(resolved[name].arrays["input/w"], values)
    assert builds[backend] == 1
    for name, result in resolved.items():
        default, integral = SIGNALS[name]
        _assert_optimal(result, integral)
        fresh = gamespec.solve(spec_from_dict(_data(default)), backend)
        np.testing.assert_allclose(fresh.arrays["input/w"], result.arrays["input/w"], atol=1e-12)
        np.testing.assert_allclose(result.controls["u"], fresh.controls["u"], atol=SOLVER_TOL)
        np.testing.assert_allclose(result.states["x"], fresh.states["x"], atol=SOLVER_TOL)
        assert result.objective == pytest.approx(fresh.objective, abs=SOLVER_TOL)


def test_backends_agree_on_a_grid_input() -> None:
    grid = Transcription(spec_from_dict(_data())).input_grid()
    inputs = {"w": np.cos(grid.time)}
    casadi_result, pyomo_result = (gamespec.solve(spec_from_dict(_data()), b) for b in BACKENDS)
    for result in (casadi_result, pyomo_result):
        _assert_optimal(result, SIGNALS["a*sin(pi*tau)"][1])
    resolved = [gamespec.compile_spec(spec_from_dict(_data()), b).solve(inputs=inputs) for b in BACKENDS]
    np.testing.assert_allclose(resolved[0].controls["u"], resolved[1].controls["u"], atol=SOLVER_TOL)
    np.testing.assert_allclose(resolved[0].states["x"], resolved[1].states["x"], atol=SOLVER_TOL)


def test_samples_in_time_are_resampled_onto_the_grid() -> None:
    """Samples of w = c t on a coarser grid (exact under linear interpolation), and another
    player's Result passed as (control_time, control): both land on the evaluation points."""
    solver = gamespec.compile_spec(spec_from_dict(_data()))
    grid = solver.compiled.input_grid()
    times = np.linspace(0.0, T, 7)
    result = solver.solve(inputs={"w": (times, 0.4 * times)})
    np.testing.assert_allclose(result.arrays["input/w"], 0.4 * grid.time, atol=1e-12)
    _assert_optimal(result, 0.2 * T**2)
    again = solver.solve(inputs={"w": (result.control_time, result.arrays["input/w"])})
    np.testing.assert_allclose(again.arrays["input/w"], result.arrays["input/w"], atol=1e-12)


def test_the_defect_check_sees_the_input_as_the_transcription_does() -> None:
    """On each interval the collocation polynomial solves x' = u + w_d exactly, w_d the degree d-1
    interpolant of the tabulated input through the collocation points; RK4 integrates that
    polynomial right-hand side exactly, so the re-integration defect is rounding alone (it would be
    of the order of the interpolation error, h^d |w^(d)|, under any other reading of the input)."""
    result = gamespec.solve(spec_from_dict(_data("sin(8*pi*tau)")))
    assert result.ok
    assert result.checks["max_defect"] < 1e-10


def test_hamiltonian_checks_only_with_a_constant_input() -> None:
    """H = u^2 + lambda (u + w) is constant on the optimum only when w is: a varying input leaves
    the Hamiltonian checks out; a constant one keeps them, and H is constant."""
    varying = gamespec.solve(spec_from_dict(_data()))
    assert "hamiltonian_variation" not in varying.checks
    constant = gamespec.solve(spec_from_dict(_data("a")))
    _assert_optimal(constant, A * T)
    assert constant.checks["hamiltonian_variation"] < 1e-6


def test_inputs_survive_save_and_load(tmp_path) -> None:
    result = gamespec.solve(spec_from_dict(_data()))
    loaded = Result.load(result.save(tmp_path / "run"))
    np.testing.assert_array_equal(loaded.arrays["input/w"], result.arrays["input/w"])


@pytest.mark.parametrize("backend", BACKENDS)
def test_bad_inputs_name_the_input(backend: str) -> None:
    solver = gamespec.compile_spec(spec_from_dict(_data()), backend)
    n = len(solver.compiled.input_grid())
    with pytest.raises(SpecError, match=r"unknown input.*xE.*declared: w") as err:
        solver.solve(inputs={"xE": np.zeros(n)})
    assert err.value.field == "inputs"
    with pytest.raises(SpecError, match=rf"one value per evaluation point \({n}") as err:
        solver.solve(inputs={"w": np.zeros(n - 1)})
    assert err.value.field == "inputs.w"
    with pytest.raises(SpecError, match="finite") as err:
        solver.solve(inputs={"w": np.full(n, np.nan)})
    with pytest.raises(SpecError, match="samples cover") as err:
        solver.solve(inputs={"w": (np.array([0.0, 0.1, 0.2]), np.zeros(3))})
    assert err.value.field == "inputs.w"


def test_free_final_time_takes_values_on_normalized_time() -> None:
    data = _data(time={"final": "free", "bounds": [0.5, 4.0]}, objective={"lagrange": "1 + u**2"})
    solver = gamespec.compile_spec(spec_from_dict(data))
    grid = solver.compiled.input_grid()
    assert grid.time is None
    with pytest.raises(SpecError, match="final time is free"):
        solver.solve(inputs={"w": (np.linspace(0, 1, 5), np.zeros(5))})
    result = solver.solve(inputs={"w": np.zeros(len(grid))})
    # w = 0: u = x_f / t_f and J = t_f + x_f^2 / t_f, least at t_f = x_f
    assert result.t_final == pytest.approx(XF, abs=SOLVER_TOL)


def test_a_kind_without_inputs_refuses_them() -> None:
    solver = gamespec.compile_spec(PROBLEMS / "ch2" / "constant_bearing_two_on_one.yaml", "analytic")
    with pytest.raises(SpecError, match="takes no grid inputs, got w"):
        solver.solve(inputs={"w": np.zeros(3)})


@pytest.mark.parametrize(
    ("change", "field", "match"),
    [
        ({"objective": {"mayer": "x_f + w"}}, "problem.objective.mayer", r"grid input.*w.*dynamics"),
        ({"boundary_constraints": ["x_f <= w"]}, "problem.boundary_constraints.0", "grid input"),
        ({"states": {"x": {"initial": 0.0, "upper": "w"}}}, "problem.states.x.upper", "grid input"),
        ({"inputs": {"w": {"default": "x"}}}, "problem.inputs.w.default", "x"),
        ({"inputs": {"w": {"default": "linear"}}}, "problem.inputs.w.default", "linear"),
        ({"inputs": {"a": {}}}, "", "names used twice: a"),
        ({"inputs": {"tau": {}}}, "", "'tau' cannot be a symbol name"),
        ({"inputs": {"sin": {}}}, "", "'sin' cannot be a symbol name"),
    ],
)
def test_inputs_where_they_cannot_be_are_refused_at_load(change: dict, field: str, match: str) -> None:
    data = _data()
    data["problem"] |= change
    with pytest.raises(SpecError, match=match) as err:
        spec_from_dict(data)
    if field:
        assert err.value.field == field


@pytest.mark.parametrize("backend", BACKENDS)
def test_inputs_enter_the_lagrange_integrand(backend: str) -> None:
    """Tracking: minimize the integral of (u - w)^2 with x' = u. H = (u - w)^2 + lambda u, lambda
    constant, so u - w = nu is constant and x_f = int w + nu T: u = w + (x_f - int w) / T."""
    data = _data(dynamics={"x": "u"}, objective={"lagrange": "(u - w)**2"})
    solver = gamespec.compile_spec(spec_from_dict(data), backend)
    grid = solver.compiled.input_grid()
    result = solver.solve(inputs={"w": np.cos(grid.time)})
    assert result.status == gamespec.Status.OPTIMAL, result.message
    expected = np.cos(grid.time) + (XF - math.sin(T)) / T
    np.testing.assert_allclose(result.controls["u"], expected, atol=SOLVER_TOL)


def test_inputs_enter_path_constraints() -> None:
    """u <= w with x' = u, x(0) = 0, x(T) = x_f: minimizing the integral of u^2 is water-filling,
    u = min(w, nu) with nu set by the integral of u = x_f. w = 1: slack, u = x_f / T = 0.5. A step,
    w = 0.3 up to t = 1 and 1 after: u = 0.3, then nu = (x_f - 0.3) / (T - 1) = 0.7 (the step sits on
    an interval boundary, so the Radau weights of each half sum to its length)."""
    data = _data("1", dynamics={"x": "u"}, path_constraints=["u <= w"])
    solver = gamespec.compile_spec(spec_from_dict(data))
    slack = solver.solve()
    np.testing.assert_allclose(slack.controls["u"], XF / T, atol=SOLVER_TOL)
    time = solver.compiled.input_grid().time
    first = time <= 1.0 + 1e-12
    step = solver.solve(inputs={"w": np.where(first, 0.3, 1.0)})
    assert step.status == gamespec.Status.OPTIMAL, step.message
    np.testing.assert_allclose(step.controls["u"], np.where(first, 0.3, 0.7), atol=SOLVER_TOL)
    assert step.checks["max_constraint_violation"] < SOLVER_TOL
