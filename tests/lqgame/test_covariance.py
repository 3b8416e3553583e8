"""Covariance steering (section 4.4): the vectorized payoff against eq. 4.56, the UCSG of eq. 4.59,
the players' CVXPY problems against closed forms, Algorithm 2 against the terminal constraint eq. 4.61,
and the smallest achievable scaling of Σ_N when the constraint cannot be met."""

from __future__ import annotations

import numpy as np
import pytest
from gamespec_cvxpy.backend import CovariancePlayers, CvxpyOptions
from scipy.linalg import sqrtm

import gamespec
from gamespec.best_response import Settings
from gamespec.lqgame.covariance import gains_to_vector, lift_gains, vector_to_gains
from gamespec.lqgame.solution import GameModel
from gamespec.result import Status
from tests.conftest import PROBLEMS
from tests.lqgame.conftest import random_game

EXAMPLE = PROBLEMS / "ch4" / "test_example.yaml"


def _direct_payoff(model: GameModel, kappa: np.ndarray, ell: np.ndarray) -> float:
    """eq. 4.56 written out with the block matrices of eq. 4.55."""
    g, lifted = model.game, model.lifted
    K = lift_gains(vector_to_gains(kappa, g.m, g.n))
    L = lift_gains(vector_to_gains(ell, g.ell, g.n))
    M = np.eye(lifted.Sigma_s.shape[0]) + lifted.B @ K + lifted.C @ L
    return float(np.trace((M.T @ lifted.Q @ M + K.T @ lifted.R @ K - L.T @ lifted.S @ L) @ lifted.Sigma_s))


def _random_gains(model: GameModel, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.standard_normal(model.covariance.g_K.size), rng.standard_normal(model.covariance.g_L.size)


def test_quadratic_form_is_eq_4_56(model: GameModel):
    kappa, ell = _random_gains(model, 0)
    assert model.covariance.payoff(kappa, ell) == pytest.approx(_direct_payoff(model, kappa, ell), rel=1e-10)


def test_unconstrained_saddle_is_stationary_and_a_saddle(model: GameModel):
    """eq. 4.59: the gradient of eq. 4.56 in the free gain entries vanishes (central differences are
    exact for a quadratic); J_Σ rises along K and falls along L."""
    kappa, ell = model.covariance.unconstrained_saddle()
    z = np.concatenate([kappa, ell])
    split = kappa.size

    def J(v: np.ndarray) -> float:
        return _direct_payoff(model, v[:split], v[split:])

    h = 1e-4
    gradient = [(J(z + h * e) - J(z - h * e)) / (2 * h) for e in np.eye(z.size)]
    np.testing.assert_allclose(gradient, 0, atol=1e-7)
    rng = np.random.default_rng(1)
    value = J(z)
    for _ in range(10):
        step = rng.standard_normal(z.size)
        assert J(np.concatenate([kappa + step[:split], ell])) >= value
        assert J(np.concatenate([kappa, ell + step[split:]])) <= value


def test_terminal_map_is_the_scaled_terminal_factor(model: GameModel):
    """``vec W = w_0 + T_WK κ + T_WL ℓ`` equals ``Σ_N^{-1/2} E_N (I + ℬK + 𝒞L) F`` (eq. 4.62)."""
    g, lifted = model.game, model.lifted
    kappa, ell = _random_gains(model, 2)
    w0, T_K, T_L = model.covariance.terminal_map()
    K = lift_gains(vector_to_gains(kappa, g.m, g.n))
    L = lift_gains(vector_to_gains(ell, g.ell, g.n))
    M = np.eye(lifted.Sigma_s.shape[0]) + lifted.B @ K + lifted.C @ L
    W = np.linalg.inv(np.real(sqrtm(g.SigmaN))) @ lifted.terminal(M) @ lifted.F
    np.testing.assert_allclose(w0 + T_K @ kappa + T_L @ ell, W.T.ravel(), atol=1e-10)


def test_whitened_controller_step_is_the_unscaled_problems_minimizer(model: GameModel):
    """The controller's SDP in whitened gains (``κ = R⁻¹z``, :mod:`gamespec.lqgame.scaling`) has
    the minimizer of eq. 4.56 under eq. 4.62 written in the gains themselves (a strictly convex
    problem: one minimizer), here with a target halfway between the UCSG's Σ_N and zero."""
    import cvxpy as cp

    g = model.game
    kappa0, ell = model.covariance.unconstrained_saddle()
    free = model.covariance.state_covariances(
        vector_to_gains(kappa0, g.m, g.n), vector_to_gains(ell, g.ell, g.n)
    )
    tight = GameModel.build(type(g)(**{**g.__dict__, "SigmaN": 0.9 * free[-1] + 1e-3 * np.eye(g.n)}))
    cov = tight.covariance
    kappa, report = CovariancePlayers(tight, CvxpyOptions()).controller_step(ell)
    assert report.status is Status.OPTIMAL
    w0, T_K, T_L = cov.terminal_map()
    x = cp.Variable(kappa.size)
    W = cp.reshape(w0 + T_L @ ell + T_K @ x, (g.n, w0.size // g.n), order="F")
    payoff = cp.quad_form(x, cp.psd_wrap(cov.H_KK)) + 2 * cov.controller_linear_term(ell) @ x
    cp.Problem(cp.Minimize(payoff), [cp.sigma_max(W) <= 1]).solve(solver="CLARABEL")
    np.testing.assert_allclose(kappa, x.value, atol=1e-5 * max(1.0, np.abs(x.value).max()))


@pytest.mark.parametrize("shape", [(4, 9), (3, 1), (1, 5)])
def test_terminal_cone_is_the_squared_spectral_norm(shape: tuple[int, int]):
    """The column form of eq. 4.61, ``Σ_j Z_j ⪯ t I`` with ``Z_j ⪰ w_j w_jᵀ``: its least ``t`` is
    ``σ_max(W)²`` (``W Wᵀ = Σ_j w_j w_jᵀ``), and with ``t = 1`` it admits ``W`` exactly when
    ``‖W‖₂ ≤ 1`` (eq. 4.62), here on either side of the boundary."""
    import cvxpy as cp

    W = np.random.default_rng(sum(shape)).standard_normal(shape)
    sigma = np.linalg.norm(W, 2)
    t = cp.Variable()
    problem = cp.Problem(cp.Minimize(t), CovariancePlayers.terminal_cone(W, t))
    problem.solve(solver="CLARABEL")
    assert t.value == pytest.approx(sigma**2, rel=1e-6)
    for factor, feasible in ((1 - 1e-3, True), (1 + 1e-3, False)):
        problem = cp.Problem(cp.Minimize(0), CovariancePlayers.terminal_cone(factor * W / sigma, 1.0))
        problem.solve(solver="CLARABEL")
        assert (problem.status == "optimal") is feasible


@pytest.mark.parametrize("seed", [0, 1])
def test_jacobi_meets_the_terminal_constraint(seed: int):
    """Algorithm 2 with a target tighter than the UCSG reaches (halfway to the least scaling the
    controller can meet): Σ_N(K, L) ⪯ Σ_N (eq. 4.61), the stopper's last gains are its best response
    to the controller's, and the constrained controller pays at least the unconstrained value."""
    loose = GameModel.build(random_game(seed))
    kappa, ell = loose.covariance.unconstrained_saddle()
    g = loose.game
    free = loose.covariance.state_covariances(
        vector_to_gains(kappa, g.m, g.n), vector_to_gains(ell, g.ell, g.n)
    )
    probe = CovariancePlayers(GameModel.build(type(g)(**{**g.__dict__, "SigmaN": free[-1]})), CvxpyOptions())
    probe.controller_step(ell)
    gamma = probe.smallest_scaling()
    assert gamma < 1
    target = (1 + gamma) / 2 * free[-1]
    model = GameModel.build(type(g)(**{**g.__dict__, "SigmaN": target}))
    outcome = CovariancePlayers(model, CvxpyOptions()).solve(Settings(tolerance=1e-7, max_iterations=200))
    assert outcome.status.ok and outcome.iterations > 0
    reached = model.covariance.state_covariances(
        vector_to_gains(outcome.kappa, g.m, g.n), vector_to_gains(outcome.ell, g.ell, g.n)
    )[-1]
    assert np.linalg.eigvalsh(target - reached).min() >= -1e-6
    np.testing.assert_allclose(outcome.ell, model.covariance.stopper_response(outcome.kappa), atol=1e-5)
    assert model.covariance.payoff(outcome.kappa, outcome.ell) >= loose.covariance.payoff(kappa, ell) - 1e-9


def test_smallest_scaling_is_tight():
    """When Σ_N is out of reach, γ* is the least scaling the controller can meet: γ*(1 + δ) Σ_N is
    feasible for its first Jacobi step, γ*(1 − δ) Σ_N is not, and γ* is at least the share of the
    last step's noise, which no gain can remove."""
    g = random_game(6)
    last_noise = g.D[-1] @ g.D[-1].T
    SigmaN = 0.5 * last_noise + 1e-4 * np.eye(g.n)
    model = GameModel.build(type(g)(**{**g.__dict__, "SigmaN": SigmaN}))
    outcome = CovariancePlayers(model, CvxpyOptions()).solve(Settings(tolerance=1e-7, max_iterations=50))
    assert outcome.status is Status.INFEASIBLE
    gamma = outcome.min_covariance_scaling
    root_inv = np.linalg.inv(np.real(sqrtm(SigmaN)))
    assert gamma >= np.linalg.eigvalsh(root_inv @ last_noise @ root_inv).max() * (1 - 1e-6)
    _, ell0 = model.covariance.unconstrained_saddle()
    for factor, feasible in ((1 + 1e-3, True), (1 - 1e-3, False)):
        scaled = GameModel.build(type(g)(**{**g.__dict__, "SigmaN": factor * gamma * SigmaN}))
        _, report = CovariancePlayers(scaled, CvxpyOptions()).controller_step(ell0)
        assert report.status.ok is feasible


HORIZON_25 = ["problem.horizon=25", "method.monte_carlo.samples=0", "method.acceleration=none"]
"""§4.5.1 at N = 25 with the plain iteration, where Jacobi's iterates spiral outwards: ε_k and ε_ℓ
alternate and each grows by about 1.4 every two iterations."""


def test_jacobi_that_diverges_says_so():
    """Algorithm 2 on the engine with a window of three periods of the alternation: the run stops
    as ``diverged`` (status not_converged) with the history, keeping the best iterate; it is not a
    solution."""
    spec = gamespec.load(EXAMPLE, HORIZON_25)
    players = CovariancePlayers(GameModel.build(spec.game()), CvxpyOptions())
    outcome = players.solve(Settings(tolerance=1e-5, max_iterations=30, window=6))
    assert outcome.status is Status.NOT_CONVERGED and "diverge" in outcome.message
    metrics = outcome.best_response
    assert metrics["outcome"] == "diverged" and not metrics["converged"]
    largest = [max(h["changes"].values()) for h in metrics["history"]]
    assert len(largest) == outcome.iterations < 30
    assert max(largest[-6:]) >= 2 * max(largest[-12:-6])


def test_a_covariance_game_past_its_iteration_limit_is_not_ok():
    """Through the solving chain: the Result's status is the engine's, with its message and
    history, and the objective is not passed off as a saddle value."""
    result = gamespec.solve(gamespec.load(EXAMPLE, [*HORIZON_25, "method.max_iterations=6"]))
    assert result.status is Status.ITERATION_LIMIT and not result.ok
    assert "did not converge in 6 iterations" in result.message
    assert result.metrics["best_response"]["iterations"] == 6
    assert len(result.metrics["convergence_history"]) == 6


def _contraction_rate(result: gamespec.Result) -> float:
    """The rate ρ per sweep a converged plain run contracted at, from its own history."""
    largest = [max(h) for h in result.metrics["convergence_history"]]
    return (largest[-1] / largest[0]) ** (1 / (len(largest) - 1))


@pytest.mark.slow
def test_damping_makes_the_horizon_25_game_converge():
    """With w = 1/2 the relaxed Jacobi map ``G_w = (1 − w) x + w G(x)`` is pulled towards 1 − w: the
    N = 25 game converges, to a point where the stopper's gains answer the controller's (eq. 4.59b)
    and Σ_N(K, L) ⪯ Σ_N. The file's accelerated run stops at ``‖G(x) − x‖ ≤ tol`` per player, so
    ``‖G_w(x) − x‖ ≤ w·tol`` and, ``G_w`` contracting at ρ, its responses lie within
    ``tol + w·tol/(1 − ρ)`` of the damped run's fixed point (which lies within ``tol·ρ/(1 − ρ)``
    of the damped run's answer)."""
    result = gamespec.solve(gamespec.load(EXAMPLE, [*HORIZON_25, "method.damping=0.5"]))
    assert result.status is Status.OPTIMAL, result.message
    assert result.checks["terminal_covariance_violation"] < 1e-6
    assert result.checks["stopper_response_gap"] < 1e-4
    accelerated = gamespec.solve(gamespec.load(EXAMPLE, HORIZON_25[:2]))
    tol, rate, w = gamespec.load(EXAMPLE).method.tolerance, _contraction_rate(result), 0.5
    bound = np.sqrt(2) * (tol + w * tol / (1 - rate)) + tol * rate / (1 - rate)
    for gains in ("K", "L"):
        assert np.abs(accelerated.arrays[gains] - result.arrays[gains]).max() <= bound


def test_the_accelerated_file_converges_at_horizon_25():
    """§4.5.1 at N = 25 as the file stands (Anderson-accelerated Jacobi): converged, Σ_N(K, L) ⪯ Σ_N,
    and the stopper's gains answer the controller's (eq. 4.59b) up to what a stop at a change ≤ tol
    leaves: ``ℓ = BR_L(κ_x)`` for the point ``κ_x`` it answered, ``‖κ − κ_x‖ ≤ tol``, and
    ``BR_L`` is affine with the slope ``Γ = −H_LL⁻¹H_LK``, so the gap is at most ``‖Γ‖₂ tol``."""
    spec = gamespec.load(EXAMPLE, ["problem.horizon=25", "method.monte_carlo.samples=0"])
    result = gamespec.solve(spec)
    assert result.status is Status.OPTIMAL, result.message
    assert result.metrics["best_response"]["acceleration"] == "anderson"
    assert result.checks["terminal_covariance_violation"] < 1e-6
    cov = GameModel.build(spec.game()).covariance
    slope = np.linalg.norm(np.linalg.solve(cov.H_LL, cov.H_KL.T), 2)
    assert result.checks["stopper_response_gap"] <= slope * spec.method.tolerance


TIGHT = {"tol_gap_abs": 1e-11, "tol_gap_rel": 1e-11, "tol_feas": 1e-11, "tol_ktratio": 1e-9}
"""Clarabel's tolerances for checks of a best response at the level of the game's own tolerance
(its defaults, 1e-8 on the duality gap, leave gains about 1e-4 apart between solver paths)."""


def test_the_accelerated_answer_is_a_mutual_best_response():
    """§4.5.1 at N = 20 (the file's accelerated Jacobi, Clarabel at :data:`TIGHT`): the returned
    gains are the responses ``κ = BR_K(ℓ_x)``, ``ℓ = BR_L(κ_x)`` to a point within the last changes
    ``ε_k = ‖κ − κ_x‖``, ``ε_ℓ = ‖ℓ − ℓ_x‖`` (≤ tol). So the stopper's best response to κ, affine
    with the slope ``Γ = −H_LL⁻¹H_LK``, is ℓ within ``‖Γ‖₂ ε_k``, and the controller's, re-solved
    from scratch on ℓ, is κ within the tolerance."""
    spec = gamespec.load(EXAMPLE, ["problem.horizon=20", "method.monte_carlo.samples=0"])
    result = gamespec.solve(spec, options={"solver_options": TIGHT})
    assert result.status is Status.OPTIMAL, result.message
    model = GameModel.build(spec.game())
    cov = model.covariance
    kappa, ell = gains_to_vector(result.arrays["K"]), gains_to_vector(result.arrays["L"])
    eps_k, _ = result.metrics["convergence_history"][-1]
    slope = np.linalg.norm(np.linalg.solve(cov.H_LL, cov.H_KL.T), 2)
    assert np.linalg.norm(cov.stopper_response(kappa) - ell) <= slope * eps_k * (1 + 1e-6)
    response, report = CovariancePlayers(model, CvxpyOptions(solver_options=TIGHT)).controller_step(ell)
    assert report.status is Status.OPTIMAL
    assert np.linalg.norm(response - kappa) <= spec.method.tolerance


def test_accelerated_jacobi_finds_the_plain_fixed_point():
    """§4.5.1 at N = 20, where plain Jacobi contracts slowly (ρ from its history, about 0.5 per
    sweep): the accelerated run answers the same best responses and stops on the same rule, a
    change ≤ tol per player, so with ``G`` contracting at ρ its responses ``g = G(x)`` are within
    ``√2·tol·ρ/(1 − ρ)`` of the fixed point as well (``‖x − x*‖ ≤ ‖x − g‖ + ρ‖x − x*‖``), the plain
    run's within ``tol·ρ/(1 − ρ)``; the payoffs agree to the same order."""
    common = ["problem.horizon=20", "method.monte_carlo.samples=0"]
    plain = gamespec.solve(gamespec.load(EXAMPLE, [*common, "method.acceleration=none"]))
    accelerated = gamespec.solve(gamespec.load(EXAMPLE, common))
    assert plain.status is Status.OPTIMAL and accelerated.status is Status.OPTIMAL
    assert accelerated.iterations < plain.iterations
    tol, rate = gamespec.load(EXAMPLE).method.tolerance, _contraction_rate(plain)
    bound = (1 + np.sqrt(2)) * tol * rate / (1 - rate)
    for gains in ("K", "L"):
        assert np.abs(accelerated.arrays[gains] - plain.arrays[gains]).max() <= bound


def test_gauss_seidel_finds_the_jacobi_fixed_point():
    """Both schemes stop near a fixed point of the same best responses (§4.5.1, N = 10): a run
    stopped at a change ≤ tol is within ``tol·ρ/(1 − ρ)`` of it, ``ρ`` the contraction rate
    estimated from the run's own history."""
    settings = ["method.monte_carlo.samples=0", "method.acceleration=none"]
    runs = {
        s: gamespec.solve(gamespec.load(EXAMPLE, [*settings, f"method.scheme={s}"]))
        for s in ("jacobi", "gauss_seidel")
    }
    assert all(r.status is Status.OPTIMAL for r in runs.values())
    tol = gamespec.load(EXAMPLE).method.tolerance
    bound = sum(tol * _contraction_rate(run) / (1 - _contraction_rate(run)) for run in runs.values())
    for gains in ("K", "L"):
        gap = np.abs(runs["gauss_seidel"].arrays[gains] - runs["jacobi"].arrays[gains]).max()
        assert gap <= bound + 1e-7
