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

from dataclasses import replace

import numpy as np
import pytest
from gamespec_levelset.game import linearized_game
from gamespec_levelset.players import (
    EvaderStep,
    GamePlayer,
    LowerValue,
    MinimaxEvader,
    MinimaxPursuerStep,
    PursuerStep,
    lower_value,
)

import gamespec
from gamespec.best_response import Outcome, Settings, iterate
from gamespec.flowfield.concepts import copy_room, saddle_gap, solution_concept
from gamespec.flowfield.covariance_game import CovarianceGame, PlayerBounds, Strategy
from gamespec.flowfield.problem import evaluate_game
from gamespec.solving import transformed
from tests.conftest import PROBLEMS
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
    ("field", "payoff"),
    [
        (linear_field, "trace"),
        (vortex_field, "trace"),
        pytest.param(vortex_field, "frobenius", marks=pytest.mark.slow),
    ],
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


def test_symmetry_alone_does_not_rule_out_a_saddle():
    """The README's two properties — ``Tᵉ = −Tᵖ`` and an evader set symmetric in its gains — hold for
    ``J = (5 + p − e)²``, ``p ∈ [−3, 3]``, ``e ∈ [−1, 1]``, which has a pure saddle at ``(−3, −1)``
    (value 9, by enumeration on a grid that holds both): the project's concept decision says
    ``saddle``. What fails there is the feasibility condition: the pursuer's answer to the passive
    evader, ``p₀ = −3``, sits on the edge of ``𝒫`` and has no room to copy ``e``
    (:func:`~gamespec.flowfield.concepts.copy_room` > 1). With room, ``J = (1 + p − e)²``, the lower
    value is ``J(p₀, 0) = 0`` and the gap is ``max_e (Tᵉe)² = 1``: no saddle."""
    p, e = np.linspace(-3, 3, 601), np.linspace(-1, 1, 201)
    for offset, saddle in ((5.0, True), (1.0, False)):
        J = (offset + p[:, None] - e[None, :]) ** 2
        lower, upper = J.min(axis=0).max(), J.max(axis=1).min()
        p0 = p[np.argmin(J[:, np.argmin(np.abs(e))])]
        room = copy_room([abs(p0)], [3.0], [1.0])
        for scheme in ("lower_value", "minimax_mixed"):
            concept = solution_concept(lower, upper, GAP, scheme)
            assert (concept == "saddle") is saddle, (offset, concept)
        if saddle:
            assert lower == pytest.approx(9.0) and upper == pytest.approx(9.0)
            i, j = np.unravel_index(
                np.argmin(np.abs(J - 9.0) + np.abs(p[:, None] + 3) + np.abs(e + 1)), J.shape
            )
            assert (p[i], e[j]) == (-3.0, -1.0)
            assert J[:, j].min() == J[i, j] == J[i, :].max()  # neither player gains by deviating
            assert room > 1
        else:
            assert room <= 1
            assert lower == pytest.approx((offset + p0) ** 2, abs=1e-12) == pytest.approx(0.0)
            assert saddle_gap(lower, upper) == pytest.approx(1.0)


@pytest.mark.parametrize("name", ["linear_flow", pytest.param("hurricane_hugo", marks=pytest.mark.slow)])
def test_the_feasibility_condition_holds_on_the_shipped_files(name):
    """On both chapter-5 files the pursuer's answer ``p₀`` to the open-loop evader leaves room to
    copy every evader gain (``p₀ + ℰ ⊆ 𝒫``), so the lower value is certified: exactly ``J(p₀, 0)`` in
    the linear flow (``Tᵖ = −Tᵉ``), within the bracket of
    :func:`~gamespec.flowfield.concepts.lower_value_bound` in the Hugo field; and the mirror bound
    ``v₊ ≥ J(p₀, 0) + ‖Tᵉκᵉ‖²`` at the evader's answer to ``p₀`` lies above that bracket: no pure
    saddle point, whatever the minimax iteration does."""
    spec = gamespec.load(PROBLEMS / "ch5" / f"{name}.yaml", ["solver.options.levelset.cross_check=false"])
    game = linearized_game(evaluate_game(transformed(spec))).game
    open_loop = game.nominal()
    scale = game.value(open_loop)
    evader = EvaderStep(game, "CLARABEL", {}, scale, 1e-6, 50, open_loop[1])
    found = lower_value(PursuerStep(game, "CLARABEL", {}, scale), evader, open_loop[1], GAP, 5)
    assert isinstance(found, LowerValue)
    assert found.room <= 1 and found.bound is not None
    assert found.bound <= found.values[-1] * (1 + GAP)
    Tp, Te = game.gain_maps
    if name == "linear_flow":
        assert np.abs(Tp + Te).max() <= 1e-12 * np.abs(Tp).max() and found.defect == 0.0
    answer = evader.respond(found.pursuer)[0]
    mirror = found.values[0] + float(np.sum((Te @ answer.kappa.reshape(-1)) ** 2)) / scale
    assert mirror > found.bound * (1 + GAP)


@pytest.mark.parametrize("payoff", ["trace", "frobenius"])
def test_the_copy_bracket_bounds_every_evader_commitment(payoff):
    """In a nonlinear field (``Tᵖ + Tᵉ ≠ 0``) with room to copy, every evader commitment ``e`` (drawn
    on the boundary of its set) meets a pursuer answer ``p₀ + κᵉ`` that is feasible and keeps
    ``J`` below the bracket of :func:`~gamespec.flowfield.concepts.lower_value_bound`, and the
    pursuer's own best answer does at least as well: ``min_p J(p, e) ≤ bound`` (so ``v₋ ≤ bound``)."""
    game, _ = small_game(vortex_field(), payoff, feedforward="nominal")
    game = replace(game, bounds=(PlayerBounds(4.0, 0.1, 0.8, 0.01), game.bounds[1]))  # room to copy
    open_loop = game.nominal()
    scale = game.value(open_loop)
    pursuer = PursuerStep(game, "CLARABEL", {}, scale)
    evader = EvaderStep(game, "CLARABEL", {}, scale, 1e-6, 50, open_loop[1])
    found = lower_value(pursuer, evader, open_loop[1], GAP, 5)
    assert isinstance(found, LowerValue) and found.room <= 1 and found.defect > 0
    p0 = pursuer.respond(open_loop[1])[0]
    rng = np.random.default_rng(0)
    for _ in range(20):
        z = rng.standard_normal((game.N - 1, 8))
        z *= (evader.radii / np.linalg.norm(z, axis=1))[:, None]
        kappa = np.zeros((game.N, 2, 4))
        kappa[1:] = np.einsum("kij,kj->ki", evader.inverse_maps, z).reshape(-1, 2, 4)
        committed = Strategy(open_loop[1].V, kappa)
        copy = Strategy(p0.V, p0.kappa + kappa)
        spread = np.linalg.norm(
            np.einsum("kij,kj->ki", pursuer.spread_maps, copy.kappa[1:].reshape(-1, 8)), axis=1
        )
        assert np.all(spread <= pursuer.radii * (1 + 1e-9))
        assert game.value((copy, committed)) / scale <= found.bound * (1 + 1e-9)
        answer = pursuer.respond(committed)[0]
        assert game.value((answer, committed)) / scale <= found.bound * (1 + 1e-6)
