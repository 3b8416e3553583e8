"""The Pyomo backend on its own: re-solves without a rebuild, guesses across backends, problems
beyond the shipped files (path, boundary and Lagrange terms, a time-dependent integrand, a fixed
final time from a parameter, the trapezoidal scheme), status mapping and refusals."""

from __future__ import annotations

import numpy as np
import pytest
from gamespec_pyomo.backend import PyomoBackend

import gamespec
from gamespec.ocp.transcription import Transcription
from gamespec.result import Status
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS
from tests.pyomo.cases import CONSTRAINED, atan2_file

MIN_TIME = PROBLEMS / "ch6" / "zermelo_min_time.yaml"
MAX_RANGE = PROBLEMS / "ch6" / "zermelo_max_range.yaml"
EVASION = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"


def test_constrained_problem_agrees_with_casadi() -> None:
    spec = gamespec.spec_from_dict(CONSTRAINED)
    casadi, pyomo = gamespec.solve(spec, "casadi"), gamespec.solve(spec, "pyomo")
    assert casadi.status is Status.OPTIMAL and pyomo.status is Status.OPTIMAL
    assert pyomo.objective == pytest.approx(casadi.objective, rel=1e-6)
    assert np.max(pyomo.states["v"]) == pytest.approx(CONSTRAINED["problem"]["parameters"]["vmax"], rel=1e-6)
    assert pyomo.states["x"][-1] == pytest.approx(0.9, rel=1e-6)
    np.testing.assert_allclose(pyomo.controls["a"], casadi.controls["a"], atol=1e-5)
    assert pyomo.checks["max_constraint_violation"] < 1e-7


def test_resolve_with_new_parameters_reuses_the_model() -> None:
    """Parameters are Vars held by equal bounds: a re-solve changes values, the model object stays."""
    solver = compile_spec(MIN_TIME, "pyomo")
    model = solver.compiled.model
    first = solver.solve()
    second = solver.solve(parameters={"rho": 5.0})
    assert solver.compiled.model is model
    assert model.p["rho"].value == 5.0
    reference = gamespec.solve(MIN_TIME, "casadi", parameters={"rho": 5.0})
    assert second.status is Status.OPTIMAL
    assert second.objective == pytest.approx(reference.objective, rel=1e-6)
    assert second.objective != pytest.approx(first.objective, rel=1e-3)


def test_parameter_final_time_resolves() -> None:
    """A fixed final time given by a parameter is a Var held by equal bounds too."""
    spec = gamespec.spec_from_dict(CONSTRAINED)
    solver = compile_spec(spec, "pyomo")
    longer = solver.solve(parameters={"tf": 2.0})
    assert longer.t_final == pytest.approx(2.0)
    assert longer.time[-1] == pytest.approx(2.0)
    reference = gamespec.solve(spec, "casadi", parameters={"tf": 2.0})
    assert longer.objective == pytest.approx(reference.objective, rel=1e-6)


def test_warm_start_from_the_last_solution() -> None:
    solver = compile_spec(EVASION, "pyomo")
    cold = solver.solve()
    warm = solver.solve()
    assert warm.status is Status.OPTIMAL
    assert warm.iterations < cold.iterations
    assert warm.objective == pytest.approx(cold.objective, rel=1e-8)


@pytest.mark.parametrize(("source", "target"), [("casadi", "pyomo"), ("pyomo", "casadi")])
def test_a_result_from_one_backend_seeds_the_other(source: str, target: str) -> None:
    spec = gamespec.load(EVASION)
    seed = gamespec.solve(spec, source)
    start = Transcription(spec).guess(seed.parameters, seed)
    np.testing.assert_array_equal(start.X[0], seed.states["r"])
    np.testing.assert_array_equal(start.U[0], seed.controls["theta"])
    cold = gamespec.solve(spec, target)
    warm = gamespec.solve(spec, target, guess=seed)
    assert warm.status is Status.OPTIMAL
    assert warm.iterations < cold.iterations
    assert warm.objective == pytest.approx(seed.objective, rel=1e-6)


def test_a_saved_result_file_seeds_pyomo(tmp_path) -> None:
    seed = gamespec.solve(EVASION, "casadi")
    seed.save(tmp_path / "seed")
    cold = gamespec.solve(EVASION, "pyomo")
    warm = gamespec.solve(gamespec.load(EVASION, [f"guess.result={tmp_path / 'seed'}"]), "pyomo")
    assert warm.iterations < cold.iterations
    assert warm.objective == pytest.approx(seed.objective, rel=1e-6)


def test_trapezoidal_scheme_agrees_with_casadi() -> None:
    spec = gamespec.load(MIN_TIME, ["method.scheme=trapezoidal", "method.intervals=60"])
    casadi, pyomo = gamespec.solve(spec, "casadi"), gamespec.solve(spec, "pyomo")
    # a second-order scheme on 60 intervals: both converge, the relative defect fails on both
    assert pyomo.status is casadi.status is Status.FEASIBLE
    assert [f.name for f in pyomo.failed_checks()] == [f.name for f in casadi.failed_checks()]
    assert [f.name for f in pyomo.failed_checks()] == ["max_defect_relative"]
    assert pyomo.objective == pytest.approx(casadi.objective, rel=1e-6)
    assert len(pyomo.controls["u"]) == 61


def test_iteration_limit_is_a_status_not_an_exception() -> None:
    result = gamespec.solve(MAX_RANGE, "pyomo", options={"max_iter": 2})
    assert result.status is Status.ITERATION_LIMIT
    assert "Maximum Number of Iterations" in result.message


def test_unknown_solver_option_value_is_a_spec_error(cli) -> None:
    code, _, err = cli("solve", MIN_TIME, "--backend", "pyomo", "--set", "solver.options.pyomo.solver=knitro")
    assert code == 2
    assert "solver.options.pyomo.solver" in err


def test_atan2_is_refused_with_exit_2(cli, tmp_path) -> None:
    """Pyomo has no atan2: the backend says so in one line, exit code 2, no traceback."""
    code, _, err = cli("solve", atan2_file(tmp_path), "--backend", "pyomo")
    assert code == 2
    assert "atan2" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


def test_missing_feature_is_exit_2(cli, monkeypatch) -> None:
    """A backend without a feature the problem needs is refused before compiling."""
    monkeypatch.setattr(PyomoBackend, "features", frozenset({"ode"}))
    code, _, err = cli("solve", MIN_TIME, "--backend", "pyomo")
    assert code == 2
    assert err.strip() == "error: backend 'pyomo' lacks free_final_time"


def test_backends_command_names_the_executable(cli) -> None:
    code, out, _ = cli("backends")
    assert code == 0
    assert PyomoBackend.available().reason.split()[0] in out


def test_an_infeasible_problem_is_a_failed_result_with_exit_1(cli) -> None:
    """|x2| <= t, so x1(t_f) <= t_f + rho t_f^2 / 2 = 0.4 < 2 for t_f <= 0.2: no feasible point."""
    too_short = gamespec.solve(gamespec.load(MIN_TIME, ["problem.time.bounds=[0.05, 0.2]"]), "pyomo")
    assert not too_short.ok
    code, _, err = cli("solve", MIN_TIME, "--backend", "pyomo", "--set", "problem.time.bounds=[0.05, 0.2]")
    assert code == 1
    assert len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_parameter_free_regulator_matches_the_riccati_closed_form(backend: str) -> None:
    """min ∫(x² + u²) dt, x' = u, x(0) = 1 on [0, T], x(T) free: the Riccati equation p' = p² - 1,
    p(T) = 0 gives p(t) = tanh(T - t), J = tanh(T) and u = -tanh(T - t) x."""
    spec = gamespec.spec_from_dict(
        {
            "kind": "optimal_control",
            "name": "scalar_regulator",
            "problem": {
                "states": {"x": {"initial": 1.0}},
                "controls": {"u": {}},
                "dynamics": {"x": "u"},
                "objective": {"lagrange": "x**2 + u**2"},
                "time": {"final": 1.0},
            },
            "method": {"intervals": 10, "degree": 3},
        }
    )
    result = gamespec.solve(spec, backend)
    assert result.objective == pytest.approx(np.tanh(1.0), rel=1e-7)
    x = np.interp(result.control_time, result.time, result.states["x"])
    np.testing.assert_allclose(result.controls["u"], -np.tanh(1.0 - result.control_time) * x, atol=1e-4)
