"""Best responses honest about convergence, game Results that say which solution they found, and
the Riccati existence test — each checked against an independent reference.

The scalar zero-sum LQ game ``ẋ = a x + u + v``, ``J = ½ s x(T)² + ½∫(q x² + u² − γ² v²) dt``
(u minimizing, v maximizing) has the open-loop saddle value ``½ P(0) x0²`` with the Riccati
equation ``−Ṗ = 2aP + q − (1 − 1/γ²) P²``, ``P(T) = s`` (integrated here with SciPy, independently
of :mod:`gamespec.games.existence`). Its maximizer alone faces ``−J``, whose Riccati equation
``−Ṁ = 2aM − q − M²/γ²``, ``M(T) = −s``, escapes backward for a = q = 0 at ``τ* = γ²/s``: no
open-loop saddle when ``T > γ²/s``, the escape at ``t = T − γ²/s``.

With a = q = 0, the Gauss–Seidel map of the best responses multiplies the change by
``s²T² / ((1 + sT)(γ² − sT))`` per sweep (:mod:`tests.games.test_lq_game`, with r = 1, q → γ²):
×50 at γ² = 1.01, s = T = 1.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from gamespec.loader import load
from gamespec.result import Status
from gamespec.solving import compile_spec
from gamespec.summaries import outcome
from tests.games.test_lq_game import FILE as CH7
from tests.games.test_lq_game import expected

SCALAR = """
kind: differential_game
name: scalar_lq
problem:
  parameters: {a: 0.0, q: 0.0, s: 1.0, g2: 2.0, T: 1.0}
  states:
    x: {initial: 1.0}
  dynamics: {x: a*x + u + v}
  players:
    pursuer: {objective: minimize, controls: {u: {}}}
    evader: {objective: maximize, controls: {v: {}}}
  payoff:
    mayer: "s/2*x_f**2"
    lagrange: "(q*x**2 + u**2 - g2*v**2)/2"
  time: {final: T}
method: {scheme: radau, intervals: 10, degree: 1}
game: {scheme: gauss_seidel, tolerance: 1.0e-8, max_iterations: 200}
"""

NONZERO_SUM = """
kind: differential_game
name: two_minimizers
problem:
  parameters: {s1: 1.0, s2: 2.0, T: 1.0}
  states:
    x: {initial: 1.0}
  dynamics: {x: u1 + u2}
  players:
    first:
      objective: minimize
      controls: {u1: {}}
      payoff: {mayer: "s1/2*x_f**2", lagrange: "u1**2/2"}
    second:
      objective: minimize
      controls: {u2: {}}
      payoff: {mayer: "s2/2*x_f**2", lagrange: "u2**2/2"}
  time: {final: T}
method: {scheme: radau, intervals: 10, degree: 1}
game: {scheme: gauss_seidel, tolerance: 1.0e-9, max_iterations: 100}
"""


@pytest.fixture
def scalar(tmp_path):
    path = tmp_path / "scalar.yaml"
    path.write_text(SCALAR)
    return lambda *sets: load(path, list(sets))


def riccati_value(a: float, q: float, s: float, g2: float, T: float, x0: float) -> float:
    """``½ P(0) x0²`` from the game's Riccati equation (module docstring), by SciPy."""
    sol = solve_ivp(
        lambda _, P: [2 * a * P[0] + q - (1 - 1 / g2) * P[0] ** 2], (0.0, T), [s], rtol=1e-13, atol=1e-15
    )
    return 0.5 * float(sol.y[0, -1]) * x0**2


def test_a_zero_sum_lq_game_is_optimal_only_within_its_tolerance_of_the_riccati_value(scalar):
    """a = −1/2, q = 1, γ² = 2 on Radau degree 4 (transcription error far below 1e-8): the value is
    within ``game.tolerance`` of the Riccati value (the responses' accepted warm starts left 2.9e-8
    before the players' tol was tied to the game's) and the gap is a passed check."""
    spec = scalar("problem.parameters.a=-0.5", "problem.parameters.q=1", "method.degree=4")
    result = compile_spec(spec).solve()
    p = spec.problem.parameters
    want = riccati_value(p["a"], p["q"], p["s"], p["g2"], p["T"], 1.0)
    assert result.status is Status.OPTIMAL, result.message
    assert abs(result.objective - want) <= spec.game.tolerance
    m = result.metrics
    assert m["solution_concept"] == "saddle" and m["information"] == "open_loop"
    assert m["payoffs"]["pursuer"] == result.objective
    assert m["payoffs"]["evader"] == pytest.approx(result.objective, abs=1e-14)
    assert result.checks["saddle_gap"] == m["saddle_gap"] <= spec.game.tolerance
    assert m["checks_passed"]["saddle_gap"] and m["check_tolerances"]["saddle_gap"] == spec.game.tolerance
    assert m["value_bounds"]["lower"] <= want + 1e-12 and want - 1e-12 <= m["value_bounds"]["upper"]
    assert abs(m["existence"]["riccati_value"] - want) <= 1e-10


def test_the_chapter_7_file_ends_without_a_jump():
    """The payoff after the last sweep stays within the tolerance of the one before and the value
    is the closed-form saddle's 10/7 (it jumped by 1.4e-7 when a player accepted its warm start)."""
    spec = load(CH7)
    result = compile_spec(spec).solve()
    history = result.metrics["best_response"]["pursuer"]["history"]
    assert result.ok and result.metrics["solution_concept"] == "saddle"
    assert abs(history[-1]["payoff"] - history[-2]["payoff"]) <= spec.game.tolerance
    assert result.objective == pytest.approx(expected(spec)["payoff"], abs=spec.game.tolerance)


def test_a_diverging_gauss_seidel_stops_before_a_player_fails(scalar):
    """×50 per sweep: the run ends ``not_converged`` as diverging within four sweeps (a player's
    IPOPT failed at the sixth before), returning the best (first) iterate with its gap."""
    result = compile_spec(scalar("problem.parameters.g2=1.01")).solve()
    run = result.metrics["best_response"]["pursuer"]
    assert result.status is Status.NOT_CONVERGED and "diverging" in result.message
    assert run["outcome"] == "diverged" and run["failed_player"] is None and run["iterations"] <= 4
    assert run["best_iteration"] == 0 and result.metrics["solution_concept"] == "none"
    changes = [max(h["changes"].values()) for h in run["history"]]
    np.testing.assert_allclose(np.array(changes[1:]) / np.array(changes[:-1]), 50.0, rtol=1e-3)


def test_slow_damped_convergence_is_not_called_cycling(scalar):
    """γ² = 1.2 (undamped ×2.5 per sweep) with damping 0.1 contracts slowly: at its limit the run
    says it was converging and at what rate; it is not cycling."""
    result = compile_spec(
        scalar("problem.parameters.g2=1.2", "game.damping=0.1", "game.max_iterations=40")
    ).solve()
    run = result.metrics["best_response"]["pursuer"]
    assert result.status is Status.ITERATION_LIMIT and run["outcome"] == "iteration_limit"
    assert "converging slowly" in result.message and "cycl" not in result.message


def test_a_nonzero_sum_game_reports_both_payoffs_and_its_nash_gap(tmp_path):
    """Two minimizers of ``J_i = ½ s_i x(T)² + ½∫u_i²`` with ``ẋ = u1 + u2``: the open-loop Nash
    controls are ``u_i = −s_i x(T)`` (constant costates), ``x(T) = x0 / (1 + T(s1 + s2))`` and
    ``J_i = ½ s_i x(T)² (1 + T s_i)``. Both payoffs are reported, the objective is the first
    player's, and the Nash gap is within the tolerance."""
    path = tmp_path / "nonzero.yaml"
    path.write_text(NONZERO_SUM)
    spec = load(path)
    result = compile_spec(spec).solve()
    p = spec.problem.parameters
    xT = 1.0 / (1 + p["T"] * (p["s1"] + p["s2"]))
    want = {name: 0.5 * s * xT**2 * (1 + p["T"] * s) for name, s in (("first", p["s1"]), ("second", p["s2"]))}
    m = result.metrics
    assert result.status is Status.OPTIMAL and m["solution_concept"] == "open_loop_nash"
    for name, value in want.items():
        assert m["payoffs"][name] == pytest.approx(value, abs=1e-9)
    assert result.objective == m["payoffs"]["first"]
    assert -1e-12 <= m["saddle_gap"] <= spec.game.tolerance
    assert m["checks_passed"]["saddle_gap"]
    rows = dict(outcome(result))
    assert rows["payoff (second)"] == m["payoffs"]["second"] and "Nash gap" in rows


def test_a_gap_beyond_the_tolerance_is_said(scalar):
    """Stopped after two sweeps, the iterate is far from the saddle: its gap is a failed check,
    named in the message and flagged in the summary."""
    result = compile_spec(scalar("game.max_iterations=2")).solve()
    m = result.metrics
    assert result.status is Status.ITERATION_LIMIT
    assert m["saddle_gap"] > m["check_tolerances"]["saddle_gap"] and not m["checks_passed"]["saddle_gap"]
    assert "saddle gap" in result.message and "exceeds the tolerance" in result.message
    assert "exceeds the tolerance" in dict(outcome(result))["saddle gap"]


def test_the_riccati_test_refuses_a_game_without_a_saddle(scalar):
    """γ² = 0.8 < sT: the maximizer's Riccati equation escapes at t = T − γ²/s = 0.2 (module
    docstring); the game is refused as unbounded before any best response, with that time."""
    spec = scalar("problem.parameters.g2=0.8")
    result = compile_spec(spec).solve()
    p = spec.problem.parameters
    escape = p["T"] - p["g2"] / p["s"]
    existence = result.metrics["existence"]
    assert result.status is Status.UNBOUNDED and "best_response" not in result.metrics
    assert existence["riccati"] == "maximizer" and existence["escape_time"] == pytest.approx(escape, abs=1e-6)
    assert "escapes at t = 0.2 " in result.message
    assert result.metrics["solution_concept"] == "none"


def test_the_riccati_test_says_when_it_does_not_apply(scalar):
    """A control bound makes the game other than LQ: the test is skipped, with the reason."""
    result = compile_spec(scalar("problem.players.pursuer.controls.u.upper=5")).solve()
    existence = result.metrics["existence"]
    assert result.ok and not existence["checked"] and "control bounds" in existence["reason"]


@pytest.mark.slow
def test_damped_jacobi_down_to_the_solvers_accuracy_is_not_cycling(scalar):
    """Jacobi with damping 0.1 to a tolerance of 1e-12 (γ² = 1.2): the players' accepted warm
    starts once stalled the change near 5e-8 and the run was called cycling after 204 sweeps; with
    the players' tol tied to the game's it converges or says it is still converging."""
    spec = scalar(
        "problem.parameters.g2=1.2",
        "game.damping=0.1",
        "game.scheme=jacobi",
        "game.tolerance=1e-12",
        "game.max_iterations=300",
    )
    result = compile_spec(spec).solve()
    run = result.metrics["best_response"]["pursuer"]
    assert run["outcome"] in ("converged", "iteration_limit"), result.message
    if run["outcome"] == "iteration_limit":
        assert "converging slowly" in result.message
    assert result.metrics["payoffs"]["pursuer"] == pytest.approx(3 / 7, abs=1e-10)


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        ("problem.dynamics.x=sin(x) + u + v", "not linear"),
        ("problem.dynamics.x=x*u + v", "not linear"),
        ("problem.payoff.lagrange=abs(u) - g2*v**2", "not quadratic"),
        ("problem.payoff.lagrange=t*u**2 - g2*v**2", "not quadratic"),
        ("problem.payoff.mayer=x_f**4", "not quadratic"),
        ("problem.players.evader.payoff={mayer: 0, lagrange: v**2}", "not zero-sum"),
    ],
)
def test_the_riccati_test_skips_what_is_not_linear_quadratic(scalar, change, reason):
    from gamespec.games.existence import existence
    from gamespec.games.lq_structure import lq_form

    spec = scalar(change)
    verdict = existence(lq_form(spec), spec.problem.parameters)
    assert not verdict.checked and not verdict.refused and reason in verdict.reason


def test_a_payoff_convex_in_the_maximizer_is_refused(scalar):
    """``+γ² v²`` in the integrand: the maximizer's problem is unbounded whatever the horizon."""
    result = compile_spec(scalar("problem.payoff.lagrange=(u**2 + g2*v**2)/2")).solve()
    assert result.status is Status.UNBOUNDED and "not strictly concave" in result.message
