"""Why Gauss–Seidel (Algorithm 3) cannot converge on the covariance game, and what the ``minimax``
scheme certifies instead, on the small games of the conftest.

In a linear flow both agents have the same Jacobian, so the same transition matrices: the gain
maps satisfy ``Tᵖ = −Tᵉ`` and ``J`` depends on ``κᵖ − κᵉ`` only. The evader's set is symmetric in its
gains, and ``J(p, e) + J(p, ẽ) = 2‖c(p)‖² + 2‖Tᵉκᵉ‖²`` for the mirror ``ẽ = (V, −κᵉ)``; so
``min_p max_e J ≥ min_p J(p, 0) + max_e ‖Tᵉκᵉ‖²``, above the value the pursuer reaches against any
evader strategy it can copy: no pure saddle point, and Gauss–Seidel, whose fixed points are
exactly the pure saddle points, cycles. ``J`` is convex in the pursuer's gains, so in the mixed
extension the pursuer has a pure optimal strategy and the value is ``min_p max_e J`` (Bohnenblust,
Karlin and Shapley 1950); the ``minimax`` scheme computes it by outer approximation.
"""

from __future__ import annotations

import numpy as np
import pytest
from gamespec_levelset.players import EvaderStep, GamePlayer, MinimaxEvader, MinimaxPursuerStep, PursuerStep

from gamespec.best_response import Outcome, Settings, iterate
from gamespec.flowfield.covariance_game import CovarianceGame
from tests.flowfield.conftest import linear_field, small_game, vortex_field

SETTINGS = Settings(scheme="gauss_seidel", tolerance=5e-3, max_iterations=20)
GAP = 1e-3


def _run(game: CovarianceGame, minimax: bool):
    open_loop = game.nominal()
    scale = game.value(open_loop)
    evader = EvaderStep(game, "CLARABEL", {}, scale, 1e-6, 50, open_loop[1])
    if minimax:
        pursuer = MinimaxPursuerStep(game, "CLARABEL", {}, scale, SETTINGS.tolerance)
        answer = MinimaxEvader(evader, pursuer, GAP, open_loop[1])
    else:
        pursuer, answer = PursuerStep(game, "CLARABEL", {}, scale), evader
    players = [GamePlayer("pursuer", pursuer), GamePlayer("evader", answer)]
    run = iterate(players, {"pursuer": open_loop[0], "evader": open_loop[1]}, SETTINGS)
    return run, pursuer, evader, scale


def test_gauss_seidel_cycles_in_a_linear_flow():
    game, _ = small_game(linear_field(), feedforward="nominal")
    Tp, Te = game.gain_maps
    assert np.abs(Tp + Te).max() <= 1e-12 * np.abs(Tp).max()
    run, pursuer, evader, _ = _run(game, minimax=False)
    assert run.outcome is Outcome.CYCLING, run.message
    # the cycle: the evader's answers alternate between mirror images, each far from the last
    last, before = evader.log.responses[-1], evader.log.responses[-2]
    np.testing.assert_allclose(last.kappa, -before.kappa, atol=1e-2 * np.abs(last.kappa).max())
    # the pursuer that knows which one is played copies it and reaches the same payoff against
    # either; its last strategy faces at least their mean ‖c‖² + ‖Tᵉκᵉ‖² from the better one
    copies = [game.value((pursuer.respond(e)[0], e)) for e in (last, before)]
    assert copies[0] == pytest.approx(copies[1], rel=1e-4)
    p = run.strategies["pursuer"]
    assert max(copies) < (game.value((p, last)) + game.value((p, before))) / 2


@pytest.mark.parametrize(
    ("field", "payoff"), [(linear_field, "trace"), (vortex_field, "trace"), (vortex_field, "frobenius")]
)
def test_minimax_stops_with_a_certified_value(field, payoff):
    """At the stop: the multipliers are a mixed strategy (≥ 0, sum 1) on the support points where
    ``J(p*, e_j) = t`` (complementary slackness), no support point exceeds ``t``, the evader's answer
    to ``p*`` stays below ``(1 + gap) t``, and ``t`` is at least what the pursuer's best response to
    the passive evader (the first support point) reaches."""
    game, _ = small_game(field(), payoff, feedforward="nominal")
    run, pursuer, evader, scale = _run(game, minimax=True)
    assert run.converged, run.message
    p, t, w = run.strategies["pursuer"], pursuer.bound, pursuer.weights
    values = np.array([game.value((p, e)) / scale for e in pursuer.support])
    assert np.all(w >= 0) and w.sum() == pytest.approx(1.0)
    assert values.max() <= t * (1 + 1e-6)
    assert w @ values == pytest.approx(t, rel=1e-5)
    answer = evader.respond(p)[0]
    assert game.value((p, answer)) / scale <= t * (1 + GAP)
    passive = game.nominal()[1]
    assert t >= game.value((PursuerStep(game, "CLARABEL", {}, scale).respond(passive)[0], passive)) / scale


def test_pursuer_feedback_against_a_passive_evader_keeps_the_mean_and_lowers_the_payoff():
    """With ``V = Û`` (feedforward nominal) the means are those of open loop whatever the gains
    (eq. 5.31a), so eq. 5.39 compares covariances only; the pursuer's answer to the open-loop evader
    is no worse for it than its own open loop (a feasible point), and meets eqs. 5.35–5.36."""
    game, _ = small_game(vortex_field(), feedforward="nominal")
    open_loop = game.nominal()
    scale = game.value(open_loop)
    response, report = PursuerStep(game, "CLARABEL", {}, scale).respond(open_loop[1])
    assert report.status.ok
    np.testing.assert_allclose(response.V, open_loop[0].V, atol=1e-7)
    mean_open, _ = game.relative(open_loop)
    mean_closed, _ = game.relative((response, open_loop[1]))
    np.testing.assert_allclose(mean_closed, mean_open, atol=1e-7)
    assert game.value((response, open_loop[1])) <= scale * (1 + 1e-6)
    assert max(game.violations((response, open_loop[1])).values()) <= 1e-6
