"""The best-response engine on zero-sum quadratic games whose saddle point and iteration maps are
known in closed form.

``J(u, v) = ½uᵀAu + uᵀCv − ½vᵀBv + aᵀu + bᵀv`` with ``A, B ≻ 0``, u minimizing and v maximizing:
the best responses are ``u = −A⁻¹(Cv + a)``, ``v = B⁻¹(Cᵀu + b)`` and the saddle point solves
``[[A, C], [Cᵀ, −B]] [u; v] = −[a; b]``. The Jacobi map ``[[0, −A⁻¹C], [B⁻¹Cᵀ, 0]]`` has the purely
imaginary eigenvalues ``±iσ`` (``σ²`` the eigenvalues of ``A⁻¹CB⁻¹Cᵀ``), so Jacobi converges iff
``σ_max < 1``, cycles at ``σ = 1`` and spirals outwards beyond; Gauss–Seidel's map on v is
``−B⁻¹CᵀA⁻¹C`` (eigenvalues ``−σ²``), twice the rate per sweep. Damping ``w`` moves the Jacobi
eigenvalues to ``1 − w ± iwσ``, inside the unit disc iff ``w < 2/(1 + σ²)``.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from gamespec.best_response import (
    Outcome,
    Settings,
    StepReport,
    VectorPlayer,
    iterate,
)
from gamespec.lqgame.solution import GameModel
from gamespec.result import Result, Status
from tests.lqgame.conftest import random_game


class QuadraticGame:
    """The game of the module docstring with coupling ``C`` scaled so that ``σ_max = sigma``."""

    def __init__(self, sigma: float, seed: int = 0, n: int = 3, m: int = 2) -> None:
        rng = np.random.default_rng(seed)
        X, Y = rng.standard_normal((n, n)), rng.standard_normal((m, m))
        self.A, self.B = X @ X.T + n * np.eye(n), Y @ Y.T + m * np.eye(m)
        C = rng.standard_normal((n, m))
        coupling = np.linalg.solve(self.A, C) @ np.linalg.solve(self.B, C.T)
        current = np.sqrt(np.linalg.eigvals(coupling).real.max())
        self.C = C * sigma / current
        self.a, self.b = rng.standard_normal(n), rng.standard_normal(m)

    def saddle(self) -> tuple[np.ndarray, np.ndarray]:
        K = np.block([[self.A, self.C], [self.C.T, -self.B]])
        z = -np.linalg.solve(K, np.concatenate([self.a, self.b]))
        return z[: self.a.size], z[self.a.size :]

    def payoff(self, s: dict[str, np.ndarray]) -> float:
        u, v = s["u"], s["v"]
        return float(0.5 * u @ self.A @ u + u @ self.C @ v - 0.5 * v @ self.B @ v + self.a @ u + self.b @ v)

    def players(self) -> list[VectorPlayer]:
        ok = StepReport(Status.OPTIMAL)
        return [
            VectorPlayer("u", lambda o: (-np.linalg.solve(self.A, self.C @ o["v"] + self.a), ok)),
            VectorPlayer("v", lambda o: (np.linalg.solve(self.B, self.C.T @ o["u"] + self.b), ok)),
        ]

    def start(self) -> dict[str, np.ndarray]:
        return {"u": np.zeros(self.a.size), "v": np.zeros(self.b.size)}


@pytest.mark.parametrize("scheme", ["jacobi", "gauss_seidel"])
def test_converges_to_the_closed_form_saddle(scheme: str):
    game = QuadraticGame(sigma=0.6)
    run = iterate(game.players(), game.start(), Settings(scheme=scheme, tolerance=1e-12), game.payoff)
    assert run.outcome is Outcome.CONVERGED and run.status is Status.OPTIMAL and run.message == ""
    u, v = game.saddle()
    # the error left after a change ≤ tol is at most tol · σ/(1 − σ) per player
    np.testing.assert_allclose(run.strategies["u"], u, atol=1e-10)
    np.testing.assert_allclose(run.strategies["v"], v, atol=1e-10)
    assert run.history[-1].payoff == pytest.approx(game.payoff({"u": u, "v": v}), abs=1e-10)
    assert all(r.status is Status.OPTIMAL and r.responses == run.iterations for r in run.players.values())


def test_gauss_seidel_needs_about_half_the_sweeps():
    """Spectral radius σ per Jacobi sweep against σ² per Gauss–Seidel sweep."""
    game = QuadraticGame(sigma=0.8)
    runs = {
        scheme: iterate(game.players(), game.start(), Settings(scheme=scheme, tolerance=1e-10))
        for scheme in ("jacobi", "gauss_seidel")
    }
    assert all(r.converged for r in runs.values())
    ratio = runs["gauss_seidel"].iterations / runs["jacobi"].iterations
    assert 0.35 < ratio < 0.65


def test_jacobi_at_unit_spectral_radius_cycles():
    """σ = 1 in one dimension: the Jacobi map is a rotation by 90°, the iterates return after four sweeps."""
    ok = StepReport(Status.OPTIMAL)
    players = [
        VectorPlayer("u", lambda o: (-o["v"] - 1.0, ok)),
        VectorPlayer("v", lambda o: (o["u"] + 0.5, ok)),
    ]
    run = iterate(players, {"u": np.array([3.0]), "v": np.array([0.0])}, Settings(max_iterations=100))
    assert run.outcome is Outcome.CYCLING and run.status is Status.NOT_CONVERGED
    assert run.iterations == 4
    assert "cycle" in run.message


def test_jacobi_beyond_unit_spectral_radius_diverges_and_damping_fixes_it():
    """σ = 2: plain Jacobi and Gauss–Seidel grow; damping w = 1/(1 + σ²) = 0.2 (the best w) converges
    to the saddle, and w = 0.5 > 2/(1 + σ²) = 0.4 still diverges."""
    game = QuadraticGame(sigma=2.0, seed=1)
    for scheme in ("jacobi", "gauss_seidel"):
        run = iterate(game.players(), game.start(), Settings(scheme=scheme, max_iterations=200))
        assert run.outcome is Outcome.DIVERGED and run.status is Status.NOT_CONVERGED, scheme
        assert run.iterations < 200
        assert run.changes("u")[-1] > run.changes("u")[0]
    damped = iterate(game.players(), game.start(), Settings(damping=0.2, tolerance=1e-11, max_iterations=500))
    assert damped.converged
    u, v = game.saddle()
    np.testing.assert_allclose(damped.strategies["u"], u, atol=1e-9)
    np.testing.assert_allclose(damped.strategies["v"], v, atol=1e-9)
    too_little = iterate(game.players(), game.start(), Settings(damping=0.5, max_iterations=500))
    assert too_little.outcome is Outcome.DIVERGED


def test_slow_convergence_reaches_the_iteration_limit():
    """σ = 0.95: the change shrinks by 0.95 per sweep, far from 1e-12 after 30 sweeps."""
    game = QuadraticGame(sigma=0.95)
    run = iterate(game.players(), game.start(), Settings(tolerance=1e-12, max_iterations=30))
    assert run.outcome is Outcome.ITERATION_LIMIT and run.status is Status.ITERATION_LIMIT
    assert run.iterations == 30 and not run.converged


def _failing_once(player: VectorPlayer, call: int) -> VectorPlayer:
    """``player``, except that its ``call``-th response fails (infeasible, "empty set")."""
    calls = []

    def respond(others):
        calls.append(1)
        if len(calls) == call:
            return None, StepReport(Status.INFEASIBLE, "empty set")
        return player.respond(others)

    return VectorPlayer(player.name, respond)


def test_a_failed_player_stops_the_run_with_its_status():
    game = QuadraticGame(sigma=0.6)
    u_player, v_player = game.players()
    run = iterate([u_player, _failing_once(v_player, 3)], game.start(), Settings(scheme="gauss_seidel"))
    assert run.outcome is Outcome.PLAYER_FAILED and run.status is Status.INFEASIBLE
    assert run.failed_player == "v" and "empty set" in run.message
    assert run.iterations == 2
    assert run.players["v"].status is Status.INFEASIBLE


def test_a_non_finite_response_is_divergence():
    ok = StepReport(Status.OPTIMAL)
    players = [
        VectorPlayer("u", lambda o: (np.array([np.nan]), ok)),
        VectorPlayer("v", lambda o: (o["u"], ok)),
    ]
    run = iterate(players, {"u": np.zeros(1), "v": np.zeros(1)})
    assert run.outcome is Outcome.DIVERGED
    np.testing.assert_array_equal(run.strategies["u"], 0.0)


def test_an_inexact_response_makes_a_converged_run_feasible():
    game = QuadraticGame(sigma=0.5)
    u_player, v_player = game.players()
    inexact = VectorPlayer("v", lambda o: (v_player.respond(o)[0], StepReport(Status.FEASIBLE, "inaccurate")))
    run = iterate([u_player, inexact], game.start())
    assert run.converged and run.status is Status.FEASIBLE and "inaccurate" in run.message


def test_metrics_go_into_a_result():
    game = QuadraticGame(sigma=0.6)
    run = iterate(game.players(), game.start(), payoff=game.payoff)
    result = Result(status=run.status, message=run.message, metrics={"best_response": run.as_metrics()})
    metrics = json.loads(result.to_json(arrays=False))["metrics"]["best_response"]
    assert metrics["converged"] is True and metrics["iterations"] == run.iterations
    assert [h["changes"]["u"] for h in metrics["history"]] == run.changes("u")
    assert metrics["players"]["v"]["status"] == "optimal"


def test_the_lq_mean_game_saddle_of_prop_9():
    """The dynamic game of eq. 4.23 (no terminal target): best responses ``Ū = −H_uu⁻¹(H_uv V̄ + f_u)``
    and eq. 4.39b converge to Prop. 9's saddle point when the Jacobi map's spectral radius
    (√ρ(H_uu⁻¹H_uv H_vv⁻¹H_uvᵀ)) is below one, as it is for these games."""
    game = random_game(0)
    model = GameModel.build(type(game)(**{**game.__dict__, "muN": None}))
    mean = model.mean
    coupling = np.linalg.solve(mean.H_uu, mean.H_uv) @ np.linalg.solve(mean.H_vv, mean.H_uv.T)
    radius = np.sqrt(np.abs(np.linalg.eigvals(coupling)).max())
    assert radius < 1
    ok = StepReport(Status.OPTIMAL)
    players = [
        VectorPlayer("u", lambda o: (-np.linalg.solve(mean.H_uu, mean.H_uv @ o["v"] + mean.free_u), ok)),
        VectorPlayer("v", lambda o: (mean.stopper_response(o["u"]), ok)),
    ]
    start = {"u": np.zeros(mean.free_u.size), "v": np.zeros(mean.free_v.size)}
    U, V = mean.saddle_point()
    for scheme in ("jacobi", "gauss_seidel"):
        run = iterate(players, start, Settings(scheme=scheme, tolerance=1e-11, max_iterations=2000))
        assert run.converged, run.message
        # a stop at change ≤ tol leaves at most tol·ρ/(1 − ρ) to go (ρ = radius per Jacobi sweep,
        # radius² per Gauss–Seidel sweep), plus the roundoff of the linear solves
        rate = radius if scheme == "jacobi" else radius**2
        bound = 2 * 1e-11 * rate / (1 - rate) + 1e-12 * np.abs(U).max()
        np.testing.assert_allclose(run.strategies["u"], U, atol=bound)
        np.testing.assert_allclose(run.strategies["v"], V, atol=bound)


def _flipping_players(jitter: float, seed: int = 0) -> list[VectorPlayer]:
    """A game without a pure saddle: ``J = (u + v)²``, u ∈ [−2, 2] minimizing, v ∈ [−1, 1]
    maximizing (convex in the maximizer). ``BR_u(v) = −v`` and ``BR_v(u) = sign(u)`` (either end
    at u = 0): the lower value ``max_v min_u J = 0`` is below the upper value ``min_u max_v J = 1``,
    so Gauss–Seidel cannot have a fixed point; from v = 1 it alternates ``(−1, −1), (1, 1), …`` — a
    period-2 cycle. Each response is perturbed by at most ``jitter`` (an inexact inner solver)."""
    rng = np.random.default_rng(seed)
    ok = StepReport(Status.OPTIMAL)

    def noisy(x: float) -> np.ndarray:
        return np.array([x + jitter * rng.uniform(-1, 1)])

    return [
        VectorPlayer("u", lambda o: (noisy(-o["v"][0]), ok)),
        VectorPlayer("v", lambda o: (noisy(-1.0 if o["u"][0] < 0 else 1.0), ok)),
    ]


@pytest.mark.parametrize("jitter", [0.0, 1e-4, 3e-3])
def test_a_period_two_cycle_within_tolerance_is_cycling(jitter: float):
    """The iterates repeat every second sweep up to ``jitter`` (below and above the tolerance 1e-3)
    while each sweep moves them by about 2: reported as cycling, well before the iteration limit."""
    start = {"u": np.zeros(1), "v": np.ones(1)}
    run = iterate(
        _flipping_players(jitter), start, Settings(scheme="gauss_seidel", tolerance=1e-3, max_iterations=50)
    )
    assert run.outcome is Outcome.CYCLING and run.status is Status.NOT_CONVERGED, run.message
    assert run.iterations <= 6
    assert min(run.changes("u")[1:]) > 1.9


def test_a_slowly_converging_alternation_is_not_called_a_cycle():
    """``s_i = qⁱ`` with q = −0.9 in both players: it comes back to within (1 − |q|)/|q| ≈ 0.11 of
    its change (above ``cycle_ratio``) and converges, as the engine must report."""
    ok = StepReport(Status.OPTIMAL)
    players = [
        VectorPlayer("u", lambda o: (-0.9 * o["v"], ok)),
        VectorPlayer("v", lambda o: (o["u"].copy(), ok)),
    ]
    run = iterate(
        players,
        {"u": np.ones(1), "v": np.ones(1)},
        Settings(scheme="gauss_seidel", tolerance=1e-8, max_iterations=400),
    )
    assert run.converged, run.message


@pytest.mark.parametrize("sigma", [0.6, 2.0, 5.0])
def test_anderson_terminates_like_gmres(sigma: float):
    """On a linear sweep map Anderson acceleration with a memory of the joint dimension d is GMRES
    (Walker & Ni 2011), exact after at most d steps: one plain sweep to start, d extrapolated ones,
    and the sweep that measures the change make at most d + 2 sweeps, whether plain Jacobi
    converges (σ < 1) or spirals outwards (σ > 1). The run stops on the plain change ≤ tol and
    returns responses, here the closed-form saddle."""
    game = QuadraticGame(sigma=sigma, seed=2)
    d = game.a.size + game.b.size
    settings = Settings(tolerance=1e-10, acceleration="anderson", memory=d)
    run = iterate(game.players(), game.start(), settings, game.payoff)
    assert run.outcome is Outcome.CONVERGED and run.status is Status.OPTIMAL
    assert run.iterations <= d + 2 and run.history[-1].largest <= 1e-10
    u, v = game.saddle()
    np.testing.assert_allclose(run.strategies["u"], u, atol=1e-9)
    np.testing.assert_allclose(run.strategies["v"], v, atol=1e-9)
    assert run.as_metrics()["acceleration"] == "anderson"


def test_anderson_on_gauss_seidel_needs_the_rank_of_the_sweep():
    """A Gauss–Seidel sweep depends on the last player's strategy alone (dimension m = 2): its map
    has rank m, its minimal polynomial degree at most m + 1, so Anderson stops within m + 3 sweeps
    even with the memory cut to m."""
    game = QuadraticGame(sigma=5.0, seed=0)
    m = game.b.size
    settings = Settings(scheme="gauss_seidel", tolerance=1e-10, acceleration="anderson", memory=m)
    run = iterate(game.players(), game.start(), settings)
    assert run.converged and run.iterations <= m + 3
    np.testing.assert_allclose(run.strategies["v"], game.saddle()[1], atol=1e-9)


def test_a_failure_at_an_extrapolated_point_is_retried_at_the_responses():
    """v fails once, on its third call: a point Anderson extrapolated (the memory holds two sweeps
    by then). The engine forgets the memory, asks again at the last responses and goes on to the
    saddle; v answered once more than there were sweeps."""
    game = QuadraticGame(sigma=2.0, seed=1)
    u_player, v_player = game.players()
    settings = Settings(tolerance=1e-10, acceleration="anderson", memory=5)
    run = iterate([u_player, _failing_once(v_player, 3)], game.start(), settings)
    assert run.converged and run.status is Status.OPTIMAL
    assert run.players["v"].responses == run.iterations + 1
    np.testing.assert_allclose(run.strategies["u"], game.saddle()[0], atol=1e-9)


def test_a_failure_at_the_responses_stops_an_accelerated_run():
    """The first sweep answers the start, not an extrapolation: a failure there is the run's."""
    game = QuadraticGame(sigma=0.6)
    u_player, _ = game.players()
    failing = VectorPlayer("v", lambda o: (None, StepReport(Status.INFEASIBLE, "empty set")))
    run = iterate([u_player, failing], game.start(), Settings(acceleration="anderson"))
    assert run.outcome is Outcome.PLAYER_FAILED and run.status is Status.INFEASIBLE
    assert run.players["v"].responses == 1


def test_anderson_needs_vector_strategies():
    class Opaque:
        name = "w"

        def respond(self, others):
            return "x", StepReport(Status.OPTIMAL)

        def distance(self, a, b):
            return 0.0

    game = QuadraticGame(sigma=0.6)
    with pytest.raises(ValueError, match="vector strategies"):
        iterate([*game.players(), Opaque()], {**game.start(), "w": "x"}, Settings(acceleration="anderson"))


def _true_residual(game: QuadraticGame, s: dict[str, np.ndarray]) -> float:
    """``max_p ‖BR_p(s_{-p}) − s_p‖`` at ``s``, from the closed-form best responses."""
    u = -np.linalg.solve(game.A, game.C @ s["v"] + game.a)
    v = np.linalg.solve(game.B, game.C.T @ s["u"] + game.b)
    return max(float(np.linalg.norm(u - s["u"])), float(np.linalg.norm(v - s["v"])))


def test_a_damped_run_stops_on_the_undamped_residual():
    """With damping w = 0.2 the step is w times the best response's distance; the stopping test
    is on the distance itself, so the returned point's true fixed-point residual (closed-form best
    responses) is within a small multiple of the tolerance, not tol/w."""
    game = QuadraticGame(sigma=2.0, seed=1)
    tol = 1e-8
    run = iterate(game.players(), game.start(), Settings(damping=0.2, tolerance=tol, max_iterations=500))
    assert run.converged and run.best == run.iterations - 1
    assert _true_residual(game, run.strategies) <= 2 * tol


def test_geometric_growth_is_divergence_before_the_window_fills():
    """A Gauss–Seidel map that multiplies the change by 50 per sweep: diverging after
    ``growth_sweeps + 1`` sweeps (the window of 10 would need 20), returning the best iterate —
    the first sweep's responses."""
    ok = StepReport(Status.OPTIMAL)
    players = [
        VectorPlayer("u", lambda o: (50.0 * o["v"] + 1.0, ok)),
        VectorPlayer("v", lambda o: (o["u"].copy(), ok)),
    ]
    run = iterate(players, {"u": np.zeros(1), "v": np.zeros(1)}, Settings(scheme="gauss_seidel"))
    assert run.outcome is Outcome.DIVERGED and run.status is Status.NOT_CONVERGED
    assert run.iterations == Settings().growth_sweeps + 1 and "diverging" in run.message
    assert run.best == 0
    np.testing.assert_array_equal(run.strategies["u"], [1.0])
    np.testing.assert_array_equal(run.strategies["v"], [1.0])


def test_slow_damped_convergence_reports_its_rate_not_a_cycle():
    """Damped Jacobi (w = 0.1) on σ = 2: the map's eigenvalues are ``1 − w ± iwσ_k`` (module
    docstring), so the change falls by ``√((1 − w)² + w²σ_max²)`` ≈ 0.92 per sweep: at the limit
    the run says it is converging slowly at that observed rate."""
    game = QuadraticGame(sigma=2.0, seed=1)
    w = 0.1
    run = iterate(game.players(), game.start(), Settings(damping=w, tolerance=1e-12, max_iterations=120))
    assert run.outcome is Outcome.ITERATION_LIMIT and "converging slowly" in run.message
    radius = np.sqrt((1 - w) ** 2 + (w * 2.0) ** 2)
    assert run.rate == pytest.approx(radius, rel=0.02)
    assert run.as_metrics()["observed_rate"] == run.rate
