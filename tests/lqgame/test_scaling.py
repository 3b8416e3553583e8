"""The scaled mean QP (:class:`~gamespec.lqgame.scaling.QPScaling`) is the same problem, and the
missile endgame (§4.5.2) gives the same answer whatever the rounding: its data perturbed at the
level of a different machine's arithmetic, and Clarabel on other numerical paths."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import gamespec
from gamespec.lqgame.checks import numerical_rank
from gamespec.lqgame.mean_steering import QPData
from gamespec.lqgame.scaling import QPScaling
from gamespec.lqgame.solution import GameModel
from gamespec.result import Status
from gamespec.specs.lq_game import LQGameSpec
from gamespec.specs.lq_model import LQGame
from tests.conftest import PROBLEMS

CH4 = PROBLEMS / "ch4"
MISSILE = CH4 / "missile_endgame.yaml"

PERTURBATION = 1e-10
"""Relative noise on every datum, far above double rounding (1.1e-16), as if the file's products and
matrix exponentials had been rounded on another machine (the noise multiplies, so structural zeros,
such as the target acceleration's row of ``B``, stay zero as they do in any rounding)."""


def _kkt_solution(qp: QPData) -> np.ndarray:
    """The minimizer of ``½zᵀPz + qᵀz`` s.t. ``Az = b`` from the KKT system (dense solve)."""
    k = qp.A.shape[0]
    kkt = np.block([[qp.P, qp.A.T], [qp.A, np.zeros((k, k))]])
    return np.linalg.solve(kkt, np.concatenate([-qp.q, qp.b]))[: qp.q.size]


@pytest.mark.parametrize("name", ["missile_endgame", "test_example"])
def test_the_scaled_mean_qp_is_the_same_problem_of_order_one(name: str):
    """Unit Hessian, unit rows, a right-hand side and linear term of norm at most one, and its
    minimizer mapped back is the original's; the value is the original's divided by ``(ρ s)²``."""
    model = GameModel.build(gamespec.load(CH4 / f"{name}.yaml").game())
    original = model.mean.upper_game_qp()
    scaling = QPScaling.of(original)
    scaled = scaling.scaled(original)
    np.testing.assert_array_equal(scaled.P, 2 * np.eye(original.q.size))
    np.testing.assert_allclose(np.linalg.norm(scaled.A, axis=1), 1, rtol=1e-12)
    assert np.linalg.norm(scaled.b) <= 1 + 1e-12 and np.linalg.norm(scaled.q) <= 2 + 1e-12
    xi = _kkt_solution(scaled)
    U = _kkt_solution(original)
    np.testing.assert_allclose(scaling.unscale(xi), U, rtol=1e-9, atol=1e-9 * np.abs(U).max())

    def value(qp: QPData, z: np.ndarray) -> float:
        return 0.5 * z @ qp.P @ z + qp.q @ z

    factor = (scaling.magnitude * scaling.whitening.step) ** 2
    assert value(original, U) == pytest.approx(factor * value(scaled, xi), rel=1e-9)


def test_the_scaled_mean_qp_without_a_terminal_mean_is_the_saddle_point():
    """Without ``μ_N`` (Prop. 9) the scaled QP has no equality, and its minimizer ``−q̂/2`` maps back
    to the saddle point's ``Ū``."""
    spec = gamespec.load(CH4 / "test_example_mean_steering.yaml", ["problem.terminal.mean=null"])
    model = GameModel.build(spec.game())
    original = model.mean.upper_game_qp()
    scaling = QPScaling.of(original)
    scaled = scaling.scaled(original)
    assert scaled.A is None and np.linalg.norm(scaled.q) == pytest.approx(2)
    U, _ = model.mean.saddle_point()
    np.testing.assert_allclose(scaling.unscale(-scaled.q / 2), U, rtol=1e-9, atol=1e-12)


def _perturbed(game: LQGame, seed: int) -> LQGame:
    rng = np.random.default_rng(seed)
    noisy = {
        k: getattr(game, k) * (1 + PERTURBATION * rng.standard_normal(getattr(game, k).shape))
        for k in ("A", "B", "C", "D", "Q", "R", "S")
    }
    return dataclasses.replace(game, **noisy)


@pytest.fixture(scope="module")
def missile() -> gamespec.Result:
    return gamespec.solve(MISSILE)


def _assert_meets_the_file_test(result: gamespec.Result, n: int) -> None:
    """The checks of test_problem_files.py::test_missile_endgame and its rank test."""
    assert result.status is Status.OPTIMAL, result.message
    assert result.metrics["best_response"]["converged"]
    assert result.checks["terminal_mean_error"] < 1e-6
    assert result.checks["terminal_covariance_violation"] < 1e-6
    assert result.metrics["relative_controllability_rank"] == n - 1
    assert result.metrics["relative_controllability_rank_margin"] > 10


@pytest.mark.parametrize("seed", range(3))
def test_the_missile_endgame_survives_a_rounding_level_change_of_its_data(monkeypatch, missile, seed: int):
    """The same status and checks, and the same answer: the mean (a KKT solve) to the relative
    perturbation's order times the KKT system's condition number of the scaled QP (below 10²), the
    gains to the Jacobi tolerance (the accuracy at which Algorithm 2 stops)."""
    spec = gamespec.load(MISSILE)
    game = _perturbed(spec.game(), seed)
    monkeypatch.setattr(LQGameSpec, "game", lambda self, values=None: game)
    result = gamespec.solve(spec)
    _assert_meets_the_file_test(result, game.n)
    mean = missile.arrays["mean"]
    np.testing.assert_allclose(result.arrays["mean"], mean, atol=1e2 * PERTURBATION * np.abs(mean).max())
    np.testing.assert_allclose(result.arrays["K"], missile.arrays["K"], atol=spec.method.tolerance)


@pytest.mark.parametrize(
    "path",
    [
        {"direct_solve_method": "faer"},
        {"iterative_refinement_max_iter": 1},
        {"iterative_refinement_max_iter": 2},
    ],
    ids=["faer", "one_refinement", "two_refinements"],
)
def test_the_missile_endgame_is_the_same_on_another_numerical_path(missile, path: dict):
    """Clarabel with another factorization or fewer refinement steps of its KKT solves (what a
    different BLAS or rounding changes): the same verdicts, the mean to rounding, the gains to the
    Jacobi tolerance. Before the mean QP was scaled (its KKT condition number 2.6·10⁷), two
    refinement steps left the terminal mean 9.8·10⁻⁷ off, at the file test's 10⁻⁶."""
    spec = gamespec.load(MISSILE)
    result = gamespec.solve(MISSILE, "cvxpy", options={"solver": "CLARABEL", "solver_options": path})
    _assert_meets_the_file_test(result, spec.game().n)
    mean = missile.arrays["mean"]
    np.testing.assert_allclose(result.arrays["mean"], mean, atol=1e-12 * np.abs(mean).max())
    np.testing.assert_allclose(result.arrays["K"], missile.arrays["K"], atol=spec.method.tolerance)


@pytest.mark.parametrize("small", [1e-20, 1e-16, 1e-14, 1e-9])
def test_a_rank_decision_reports_its_distance_from_numpys_tolerance(small: float):
    """``diag(1, 0.5, small)``: numpy's rank, and the margin ``min(σ_r/τ, τ/σ_{r+1})`` with
    ``τ = 3 eps`` (σ_max = 1), small when ``small`` sits near ``τ``."""
    sv = np.array([1.0, 0.5, small])
    rank, margin = numerical_rank(sv, (3, 3))
    tolerance = 3 * np.finfo(float).eps
    assert rank == np.linalg.matrix_rank(np.diag(sv))
    expected = min(0.5 / tolerance, tolerance / small) if small <= tolerance else small / tolerance
    assert margin == pytest.approx(expected)


@pytest.mark.parametrize("name", ["test_example", "test_example_large_noise"])
def test_the_other_covariance_files_survive_a_rounding_level_change_of_their_data(monkeypatch, name: str):
    """§4.5.1 (Fig. 4.2 and 4.3) with the same noise: the same status, the mean to the
    perturbation's order, and, where the Jacobi run converges, the gains to its tolerance; the
    infeasible file's smallest scaling γ* to the perturbation's order."""
    path = CH4 / f"{name}.yaml"
    reference = gamespec.solve(path)
    spec = gamespec.load(path)
    game = _perturbed(spec.game(), 0)
    monkeypatch.setattr(LQGameSpec, "game", lambda self, values=None: game)
    result = gamespec.solve(spec)
    assert result.status is reference.status
    mean = reference.arrays["mean"]
    np.testing.assert_allclose(result.arrays["mean"], mean, atol=1e2 * PERTURBATION * np.abs(mean).max())
    if reference.status is Status.OPTIMAL:
        np.testing.assert_allclose(result.arrays["K"], reference.arrays["K"], atol=spec.method.tolerance)
    else:
        gamma = reference.metrics["min_covariance_scaling"]
        assert result.metrics["min_covariance_scaling"] == pytest.approx(gamma, rel=1e2 * PERTURBATION)
