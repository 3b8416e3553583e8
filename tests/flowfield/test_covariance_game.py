"""The covariance game (eqs. 5.27–5.36): covariances against Monte Carlo of the feedback loop,
payoff gradients against finite differences, and the players' steps (Algorithm 3)."""

from __future__ import annotations

import numpy as np
import pytest
from gamespec_levelset.players import EvaderStep, PursuerStep

from gamespec.flowfield.covariance_game import CovarianceGame, Strategy
from tests.flowfield.conftest import SMALL_STEPS as N
from tests.flowfield.conftest import small_game, vortex_field


def _game(payoff: str = "trace") -> tuple[CovarianceGame, object]:
    return small_game(vortex_field(), payoff)


def _random_strategies(game: CovarianceGame, seed: int, scale: float = 0.5) -> tuple[Strategy, Strategy]:
    rng = np.random.default_rng(seed)
    out = []
    for V in game.nominal():
        kappa = scale * rng.normal(size=(N, 2, 4))
        kappa[0] = 0
        out.append(Strategy(V.V + 0.01 * rng.normal(size=V.V.shape), kappa))
    return tuple(out)


def test_relative_mean_and_covariance_match_the_feedback_loop() -> None:
    """Eq. 5.31–5.33 (with ``Y = 𝒟_y W``) against samples of ``x_{k+1} = A_k x_k + B_k u_k + r_k +
    D_k w_k``, ``u_k = v_k + K_k y_k``, ``y_{k+1} = A_k y_k + D_k w_k`` (eqs. 5.7, 5.27, 5.28)."""
    game, model = _game()
    strategies = _random_strategies(game, 1)
    V, K = game.controls(strategies)
    n = 200_000
    rng = np.random.default_rng(2)
    x = np.tile(game.model.x0, (n, 1))
    y = np.zeros((n, 4))
    rel = []
    for k in range(N):
        w = rng.standard_normal((n, 4))
        u = V[k] + y @ K[k].T
        x = x @ model.A[k].T + u @ model.B[k].T + model.r[k] + w @ model.D[k].T
        y = y @ model.A[k].T + w @ model.D[k].T
        rel.append(x[:, :2] - x[:, 2:])
    rel = np.stack(rel, axis=1)
    mu, Sigma = game.relative(strategies)
    for k in range(N):
        S = Sigma[k]
        se = np.sqrt(np.diag(S) / n)
        assert np.all(np.abs(rel[:, k].mean(axis=0) - mu[k]) < 5 * se)
        sample = np.cov(rel[:, k].T)
        se_cov = np.sqrt((S**2 + np.outer(np.diag(S), np.diag(S))) / n)
        assert np.all(np.abs(sample - S) < 5 * se_cov)


@pytest.mark.parametrize("payoff", ["trace", "frobenius"])
@pytest.mark.parametrize("player", [0, 1])
def test_payoff_gradient_against_finite_differences(payoff: str, player: int) -> None:
    game, _ = _game(payoff)
    strategies = _random_strategies(game, 4)
    grad = game.gradient(strategies, player)
    rng = np.random.default_rng(5)
    direction = rng.normal(size=grad.shape)
    h = 1e-5

    def moved(sign: float) -> float:
        s = list(strategies)
        s[player] = Strategy(s[player].V, s[player].kappa + sign * h * direction)
        return game.value(tuple(s))

    fd = (moved(1) - moved(-1)) / (2 * h)
    assert fd == pytest.approx(float(np.sum(grad * direction)), rel=1e-6)


def test_trace_payoff_is_the_trace_of_the_relative_covariance() -> None:
    """Eq. 5.34: ``J = tr(ΔᵀΔ Σˣ) = Σ_k tr Σʳ_k``."""
    game, _ = _game()
    strategies = _random_strategies(game, 6)
    _, Sigma = game.relative(strategies)
    assert game.value(strategies) == pytest.approx(np.trace(Sigma, axis1=1, axis2=2).sum(), rel=1e-12)


@pytest.mark.parametrize("payoff", ["trace", "frobenius"])
def test_pursuer_step_never_raises_the_payoff_it_minimizes(payoff: str) -> None:
    """From any evader strategy, the pursuer's response is no worse for it than its open loop (a
    feasible point), and it satisfies eqs. 5.35–5.36."""
    game, _ = _game(payoff)
    open_loop = game.nominal()
    scale = game.value(open_loop)
    pursuer = PursuerStep(game, "CLARABEL", {}, scale)
    for seed in (0, 1):
        evader = _random_strategies(game, seed, scale=0.2)[1]
        response, report = pursuer.respond(evader)
        assert report.status.ok
        before = game.value((open_loop[0], evader))
        assert game.value((response, evader)) <= before * (1 + 1e-6)
        violations = game.violations((response, open_loop[1]))
        assert max(v for k, v in violations.items() if k.startswith("pursuer")) <= 1e-6


def test_evader_convex_concave_steps_never_lower_the_payoff() -> None:
    game, _ = _game()
    open_loop = game.nominal()
    scale = game.value(open_loop)
    evader = EvaderStep(game, "CLARABEL", {}, scale, 1e-8, 30, open_loop[1])
    response, report = evader.respond(open_loop[0])
    assert report.status.ok
    values = np.array(evader.log.steps[-1])
    assert np.all(np.diff(values) >= -1e-7 * values[:-1])
    assert values[-1] > values[0]
    violations = game.violations((open_loop[0], response))
    assert max(v for k, v in violations.items() if k.startswith("evader")) <= 1e-6


def test_closed_form_tangent_step_is_the_conic_maximizer() -> None:
    """With ``V = Û`` the evader's linearized step separates per step; its closed form against the
    conic problem (Clarabel) on the same set, for random slopes."""
    game, _ = small_game(vortex_field(), feedforward="nominal")
    open_loop = game.nominal()
    evader = EvaderStep(game, "CLARABEL", {}, game.value(open_loop), 1e-6, 30, open_loop[1])
    rng = np.random.default_rng(7)
    for _ in range(3):
        slope = rng.normal(size=8 * (N - 1))
        closed, report = evader.tangent_step(slope)
        assert report.status.ok
        evader.slope.value = slope / np.linalg.norm(slope)
        assert evader.run(evader.problem).ok
        conic = evader.strategy()
        gain = slope @ closed.kappa[1:].reshape(-1)
        assert gain == pytest.approx(slope @ conic.kappa[1:].reshape(-1), rel=1e-6)
        np.testing.assert_allclose(closed.kappa, conic.kappa, atol=1e-5 * np.abs(closed.kappa).max())
        violations = game.violations((open_loop[0], closed))
        assert max(v for k, v in violations.items() if k.startswith("evader")) <= 1e-9
