"""The chapter 4 problem files solve as they are, on both backend families, and the CLI compares
and plots them."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gamespec
from gamespec.result import Status
from tests.conftest import PROBLEMS

CH4 = PROBLEMS / "ch4"
METRICS = (
    "terminal_mean",
    "terminal_covariance",
    "target_covariance",
    "iterations",
    "relative_controllability_rank",
)


@pytest.fixture(scope="module")
def solved() -> dict[str, gamespec.Result]:
    return {p.stem: gamespec.solve(p) for p in sorted(CH4.glob("*.yaml"))}


def test_each_file_has_the_documented_metrics(solved):
    assert set(solved) == {"test_example", "test_example_large_noise", "missile_endgame"}
    for result in solved.values():
        assert result.backend == "cvxpy"
        assert all(key in result.metrics for key in METRICS)


def test_example_meets_both_targets(solved):
    """§4.5.1 with D = 0.01 I (Fig. 4.2): the mean reaches 0 and Σ_N(K, L) ⪯ Σ_N."""
    result = solved["test_example"]
    assert result.status is Status.OPTIMAL, result.message
    assert result.metrics["relative_controllability_rank"] == 4
    assert result.checks["terminal_mean_error"] < 1e-8
    assert result.checks["terminal_covariance_violation"] < 1e-7
    assert result.checks["max_constraint_violation"] < 1e-7
    assert result.iterations > 0
    assert result.checks["mean_closed_form_gap"] < 1e-8
    assert result.checks["monte_carlo_mean_z"] < 5 and result.checks["monte_carlo_covariance_z"] < 5
    history = np.array(result.metrics["convergence_history"])
    assert history[-1].max() <= gamespec.load(CH4 / "test_example.yaml").method.tolerance


def test_large_noise_is_infeasible_with_the_smallest_scaling(solved):
    """§4.5.1 with D = 0.1 I (Fig. 4.3): the last step's noise 0.01 I alone exceeds the target's
    0.001 on the velocities, so γ* ≥ 10; the mean still reaches its target."""
    result = solved["test_example_large_noise"]
    assert result.status is Status.INFEASIBLE
    assert result.metrics["min_covariance_scaling"] >= 10
    assert "γ*" in result.message
    assert result.checks["terminal_mean_error"] < 1e-8


def test_missile_endgame(solved):
    """§4.5.2: meets the terminal targets; 𝒢 has rank 3, not the full row rank the thesis reports."""
    result = solved["missile_endgame"]
    assert result.status.ok, result.message
    assert result.metrics["relative_controllability_rank"] == 3
    assert result.checks["terminal_mean_error"] < 1e-6
    assert result.checks["terminal_covariance_violation"] < 1e-6


def test_missile_with_the_thesis_target_names_the_unreachable_component():
    """With the thesis' μ_N = [0, 0, 0.1, 0.1], Lemma 11 fails on a_e (index 2)."""
    spec = gamespec.load(CH4 / "missile_endgame.yaml", ["problem.terminal.mean=[0, 0, 0.1, 0.1]"])
    result = gamespec.solve(spec)
    assert result.status is Status.INFEASIBLE
    assert result.metrics["unreachable_components"] == [2]
    assert "Lemma 11" in result.message


@pytest.mark.parametrize("name", ["test_example", "test_example_large_noise", "missile_endgame"])
@pytest.mark.parametrize("solver", ["proxqp", "clarabel"])
def test_qp_backend_mean_agrees_with_cvxpy(solved, name: str, solver: str):
    """The mean game through qpsolvers matches the CVXPY QP; the unenforced covariance is said."""
    result = gamespec.solve(CH4 / f"{name}.yaml", "qp", options={"solver": solver})
    assert result.status is Status.OPTIMAL
    assert "not enforced" in result.message
    reference = solved[name].arrays["mean"]
    scale = np.abs(reference).max()
    np.testing.assert_allclose(result.arrays["mean"], reference, atol=1e-5 * scale)


def test_compare_across_conic_solvers(cli):
    code, out, _ = cli(
        "compare", CH4 / "test_example.yaml", "--backends", "cvxpy:clarabel,cvxpy:scs", "--json"
    )
    rows = json.loads(out)
    assert code == 0
    assert [r["status"] for r in rows] == ["optimal", "optimal"]
    assert rows[1]["objective"] == pytest.approx(rows[0]["objective"], rel=1e-5)


def test_compare_across_qp_solvers(cli):
    backends = "qp:proxqp,qp:osqp,qp:clarabel"
    code, out, _ = cli("compare", CH4 / "missile_endgame.yaml", "--backends", backends, "--json")
    rows = json.loads(out)
    assert code == 0
    assert all(r["status"] == "optimal" for r in rows)
    assert all(r["objective"] == pytest.approx(rows[0]["objective"], rel=1e-6) for r in rows)


def test_solve_out_then_plot(cli, tmp_path):
    code, _, _ = cli("solve", CH4 / "test_example.yaml", "--out", tmp_path / "run")
    assert code == 0
    code, _, _ = cli("plot", tmp_path / "run")
    assert code == 0
    assert sorted(p.name for p in (tmp_path / "run").glob("*.png")) == [
        "convergence.png",
        "ellipses.png",
        "first_state.png",
    ]


def test_guess_warm_starts_the_jacobi_procedure(solved):
    """Re-solving from a converged Result's gains needs a single Jacobi iteration."""
    result = gamespec.compile_spec(CH4 / "test_example.yaml").solve(guess=solved["test_example"])
    assert result.status is Status.OPTIMAL
    assert result.iterations == 1
    np.testing.assert_allclose(result.arrays["K"], solved["test_example"].arrays["K"], atol=1e-5)


@pytest.mark.parametrize("backend", ["cvxpy", "qp"])
def test_bad_solver_options_are_one_line_errors(cli, backend: str):
    setting = f"solver.options.{backend}.solver_options.bogus=1"
    code, _, err = cli("solve", CH4 / "missile_endgame.yaml", "--backend", backend, "--set", setting)
    assert code == 2
    assert "bogus" in err and "Traceback" not in err
