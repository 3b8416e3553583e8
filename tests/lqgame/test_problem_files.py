"""The chapter 4 problem files solve as they are, on the backends that take them (``qp`` refuses a
terminal covariance), and the CLI compares and plots them."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gamespec
from gamespec.errors import UnsupportedFeature
from gamespec.lqgame.solution import GameModel
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


COVARIANCE_FILES = ["test_example", "test_example_large_noise", "missile_endgame"]


def test_each_file_has_the_documented_metrics(solved):
    assert set(solved) == {*COVARIANCE_FILES, "test_example_mean_steering"}
    for name, result in solved.items():
        spec = gamespec.load(CH4 / f"{name}.yaml")
        assert result.backend == spec.solver.backend
        assert all(key in result.metrics for key in METRICS if key != "target_covariance")
        assert ("target_covariance" in result.metrics) == (spec.problem.terminal.covariance is not None)


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
    """§4.5.2 on the file's solver (Clarabel): the Jacobi run converges and meets the terminal
    targets (eq. 4.42 on the given rows, eq. 4.61)."""
    result = solved["missile_endgame"]
    assert result.status is Status.OPTIMAL, result.message
    assert result.metrics["best_response"]["converged"]
    assert result.checks["terminal_mean_error"] < 1e-6
    assert result.checks["terminal_covariance_violation"] < 1e-6


def test_missile_endgame_cannot_steer_the_target_acceleration(solved):
    """Why 𝒢 (eq. 4.40) loses a rank in double precision, and in which direction.

    ``ȧ_e = (v − a_e)/τ_e`` involves neither the missile's command u nor another state: e_{a_e} is a
    left eigenvector of every ``A_k`` orthogonal to every ``B_k`` (PBH), so ``e_{a_e}ᵀ B̄_N = 0`` and
    ``e_{a_e}ᵀ 𝒢 = e_{a_e}ᵀ C̄_N Γ`` with the stopper's response ``Γ = −H_vv⁻¹ H_uvᵀ`` (eq. 4.39b),
    of size at most ``‖C̄_N‖ ‖H_uv‖ / λ_min(−H_vv)``; with ``S = 3·10⁸`` that bound is below numpy's
    rank tolerance, so 𝒢 has numerical rank n − 1 (not the full row rank the thesis reports) and
    its left singular vector of the smallest singular value is e_{a_e}."""
    spec = gamespec.load(CH4 / "missile_endgame.yaml")
    model = GameModel.build(spec.game())
    game, mean = model.game, model.mean
    a_e = spec.state_names.index("a_e")
    e = np.eye(game.n)[a_e]
    eps = np.finfo(float).eps
    for A, B in zip(game.A, game.B, strict=True):
        np.testing.assert_allclose(e @ A, A[a_e, a_e] * e, atol=eps)
        np.testing.assert_allclose(e @ B, 0, atol=eps)
    G, _ = mean.relative_controllability
    singular = np.linalg.svd(G, compute_uv=False)
    tolerance = singular.max() * max(G.shape) * eps
    C_N = model.lifted.terminal(model.lifted.C)
    bound = np.linalg.norm(C_N[a_e]) * np.linalg.norm(mean.H_uv, 2) / np.linalg.eigvalsh(-mean.H_vv).min()
    assert np.linalg.norm(e @ G) <= bound < tolerance
    left, _, _ = np.linalg.svd(G)
    assert abs(left[a_e, -1]) == pytest.approx(1, abs=1e-9)
    assert singular[-2] > 1e6 * tolerance
    assert solved["missile_endgame"].metrics["relative_controllability_rank"] == game.n - 1
    assert spec.problem.terminal.mean[a_e] is None


def test_missile_with_the_thesis_target_names_the_unreachable_component():
    """With the thesis' μ_N = [0, 0, 0.1, 0.1], Lemma 11 fails on a_e (index 2)."""
    spec = gamespec.load(CH4 / "missile_endgame.yaml", ["problem.terminal.mean=[0, 0, 0.1, 0.1]"])
    result = gamespec.solve(spec)
    assert result.status is Status.INFEASIBLE
    assert result.metrics["unreachable_components"] == [2]
    assert "Lemma 11" in result.message


@pytest.mark.parametrize("name", COVARIANCE_FILES)
def test_qp_refuses_a_terminal_covariance(cli, name: str):
    """A QP solver cannot enforce eq. 4.62: the qp backend says so instead of returning gains
    that miss Σ_N."""
    with pytest.raises(UnsupportedFeature, match="covariance_constraint"):
        gamespec.compile_spec(CH4 / f"{name}.yaml", "qp")
    code, out, err = cli("solve", CH4 / f"{name}.yaml", "--backend", "qp", "--json")
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1 and "covariance_constraint" in err


@pytest.mark.parametrize("solver", ["proxqp", "clarabel", "osqp"])
def test_qp_and_cvxpy_agree_on_the_mean_steering_game(solver: str):
    """§4.5.1 without Σ_N on qpsolvers and on CVXPY: the same mean, gains and payoff, and the mean
    reaches its target."""
    result = gamespec.solve(CH4 / "test_example_mean_steering.yaml", "qp", options={"solver": solver})
    reference = gamespec.solve(CH4 / "test_example_mean_steering.yaml", "cvxpy")
    for r in (result, reference):
        assert r.status is Status.OPTIMAL, r.message
        assert r.checks["terminal_mean_error"] < 1e-6
    assert result.iterations is None
    scale = np.abs(reference.arrays["mean"]).max()
    np.testing.assert_allclose(result.arrays["mean"], reference.arrays["mean"], atol=1e-6 * scale)
    np.testing.assert_allclose(result.arrays["K"], reference.arrays["K"], atol=1e-9)
    assert result.objective == pytest.approx(reference.objective, rel=1e-6)


def test_mean_steering_is_the_mean_of_the_constrained_game(solved):
    """Prop. 8: the terminal covariance does not change the mean game, so §4.5.1 with and without
    Σ_N steer the same mean."""
    with_covariance = solved["test_example"].arrays["mean"]
    np.testing.assert_allclose(
        solved["test_example_mean_steering"].arrays["mean"],
        with_covariance,
        atol=1e-6 * np.abs(with_covariance).max(),
    )


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
    code, out, _ = cli("compare", CH4 / "test_example_mean_steering.yaml", "--backends", backends, "--json")
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
    path = CH4 / "test_example_mean_steering.yaml"
    code, _, err = cli("solve", path, "--backend", backend, "--set", setting)
    assert code == 2
    assert "bogus" in err and "Traceback" not in err
