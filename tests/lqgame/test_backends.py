"""What the ``lq_stochastic_game`` backends share (:class:`~gamespec.lqgame.solution.LQCompiledModel`):
re-solves with and without new parameter values, honest statuses and messages, and the eq. 4.27
boundary reported as a failed assumption."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

import gamespec
from gamespec import spec_from_dict
from gamespec.lqgame.solution import GameModel
from gamespec.result import Status
from gamespec.specs.lq_model import LQGame
from tests.conftest import PROBLEMS

CH4 = PROBLEMS / "ch4"
MEAN_STEERING = CH4 / "test_example_mean_steering.yaml"


@pytest.mark.parametrize(("path", "backend"), [(CH4 / "test_example.yaml", "cvxpy"), (MEAN_STEERING, "qp")])
def test_a_solve_without_parameters_is_the_files_problem(path, backend: str):
    """After a solve with new values, ``solve()`` goes back to the file's values (as casadi and
    pyomo do), and gives what a fresh model gives."""
    solver = gamespec.compile_spec(path, backend)
    file_values = dict(gamespec.load(path).problem.parameters)
    noisy = solver.solve(parameters={"noise": 0.05})
    again = solver.solve()
    fresh = gamespec.compile_spec(path, backend).solve()
    assert noisy.parameters == {**file_values, "noise": 0.05}
    assert again.parameters == fresh.parameters == file_values
    np.testing.assert_allclose(again.arrays["covariance"], fresh.arrays["covariance"], atol=1e-9)
    assert not np.allclose(noisy.arrays["covariance"][-1], fresh.arrays["covariance"][-1])


def test_an_inaccurate_jacobi_step_is_named():
    """A Jacobi run whose last step the solver solved only inaccurately is ``feasible`` and says
    which step it was."""
    options = {"solver": "SCS", "solver_options": {"max_iters": 30}}
    result = gamespec.solve(CH4 / "test_example.yaml", "cvxpy", options=options)
    assert result.status is Status.FEASIBLE
    assert f"step {result.iterations}: solver reported optimal_inaccurate" in result.message
    assert result.message.startswith(("controller", "stopper"))


def test_an_inaccurate_mean_qp_is_named():
    options = {"solver": "SCS", "solver_options": {"max_iters": 5}}
    result = gamespec.solve(MEAN_STEERING, "cvxpy", options=options)
    assert result.status is Status.FEASIBLE
    assert result.message == "mean QP: solver reported optimal_inaccurate"


BOUNDARY = {
    "kind": "lq_stochastic_game",
    "problem": {
        "horizon": 2,
        "discrete": {"A": [[1]], "B": [[1]], "C": [[1]], "D": [[0.1]]},
        "cost": {"Q": [[1]], "R": [[1]], "S": [[1]]},
        "initial": {"mean": [1], "covariance": [[1]]},
    },
}
"""N = 2, scalar: ``S̄ − 𝒞ᵀQ̄𝒞 = diag(S − C²Q, S) = diag(0, 1)``, singular."""


@pytest.mark.parametrize("backend", ["cvxpy", "qp"])
def test_eq_4_27_boundary_is_a_failed_assumption(cli, tmp_path, backend: str):
    """``S̄ − 𝒞ᵀQ̄𝒞`` singular (eq. 4.27 with equality): status error with the assumption, not a
    numpy error, in Python and on the command line."""
    result = gamespec.solve(spec_from_dict(BOUNDARY), backend)
    assert result.status is Status.ERROR
    assert result.message.startswith("eq. 4.27 fails")
    assert result.metrics["assumption_4_27_min_eig"] == 0
    path = tmp_path / "boundary.yaml"
    path.write_text(yaml.safe_dump(BOUNDARY))
    code, _, err = cli("solve", path, "--backend", backend)
    assert code != 0
    assert len(err.strip().splitlines()) == 1 and "eq. 4.27" in err


def test_eq_4_27_within_roundoff_of_singular_fails():
    """``S_0`` one ulp above ``C²Q``: a positive eigenvalue at the rounding level is not eq. 4.27."""
    c = 0.1
    one = np.ones((2, 1, 1))
    S = np.array([[[np.nextafter(c * c, 1.0)]], [[1.0]]])
    game = LQGame(A=one, B=one, C=c * one, D=0.1 * one, Q=one, R=one, S=S, mu0=np.ones(1), Sigma0=np.eye(1))
    model = GameModel.build(game)
    assert model.assumptions.stopper_concavity_min_eig == 0
    assert model.assumption_failure().startswith("eq. 4.27 fails")
    assert model.unreachable_mean() is None


class _FailsFirst:
    """A stand-in for a cvxpy Problem whose first solve raises SolverError (a numerical failure)."""

    def __init__(self) -> None:
        self.calls: list[tuple[str, dict]] = []
        self.status = None

    def solve(self, solver: str, warm_start: bool, **options) -> None:
        import cvxpy as cp

        self.calls.append((solver, options))
        if len(self.calls) == 1:
            raise cp.SolverError("numerical trouble")
        self.status = "optimal"


@pytest.mark.parametrize(
    ("options", "second_call", "note"),
    [
        ({}, ("CLARABEL", {"chordal_decomposition_enable": False}), "CLARABEL failed numerically"),
        ({"retry_solver_options": {}, "fallback_solver": "SCS"}, ("SCS", {}), "SCS: optimal"),
    ],
)
def test_a_numerically_failed_step_is_retried_and_says_so(options: dict, second_call: tuple, note: str):
    """Clarabel's second attempt goes without chordal decomposition (same tolerances); a fallback
    solver is used only when the options name one; the note says what was needed."""
    from gamespec_cvxpy.backend import CvxpyOptions, _Problem

    problem = _Problem(_FailsFirst(), CvxpyOptions(**options))
    assert problem.solve() is Status.OPTIMAL
    assert problem.problem.calls[1] == second_call
    assert problem.note.startswith(note)


def test_without_a_retry_a_numerical_failure_is_reported():
    from gamespec_cvxpy.backend import CvxpyOptions, _Problem

    problem = _Problem(_FailsFirst(), CvxpyOptions(retry_solver_options={}))
    assert problem.solve() is Status.NUMERICAL_ERROR
    assert problem.reported == "a solver error" and len(problem.problem.calls) == 1


@pytest.mark.parametrize("solver", ["proxqp", "osqp", "clarabel"])
def test_qp_status_is_qpsolvers_own_optimality_check(solver: str):
    """An ``optimal`` mean QP has qpsolvers' primal and dual residuals and duality gap below
    ``QP_TOLERANCE`` times the data scale (``Solution.is_optimal``), and they are in the checks."""
    from gamespec_qp.backend import QP_TOLERANCE

    result = gamespec.solve(MEAN_STEERING, "qp", options={"solver": solver})
    assert result.status is Status.OPTIMAL, result.message
    eps = QP_TOLERANCE * result.checks["qp_data_scale"]
    assert max(result.checks[k] for k in ("qp_primal_residual", "qp_dual_residual", "qp_duality_gap")) < eps


@pytest.mark.parametrize(
    "solver_options", [{"eps_abs": 1e-2, "eps_rel": 1e-2}, {"max_iter": 10}], ids=["loose", "starved"]
)
def test_a_qp_solution_that_fails_the_check_is_not_optimal(solver_options: dict):
    """OSQP stopped far from the optimum: not reported as optimal, and the message says why."""
    options = {"solver": "osqp", "solver_options": solver_options}
    result = gamespec.solve(MEAN_STEERING, "qp", options=options)
    assert result.status is not Status.OPTIMAL
    assert result.message.startswith("mean QP: osqp")
