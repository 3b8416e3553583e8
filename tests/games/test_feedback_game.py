"""``game.information: feedback`` on differential_game files: the feedback equilibrium of an LQ game
by the coupled Riccati equations, against the scalar closed forms (issue 26 item 2).

The scalar zero-sum game of :mod:`tests.games.test_honest_equilibria` with a = q = 0, s = T = 1 has
the feedback saddle value ``½ P(0)`` with ``1/P(0) = 1 + (1 − 1/γ²)``: 3/7 at γ² = 1.2 (where the
open-loop saddle has the same value) and 2/3 at γ² = 0.8, where the open-loop game has no saddle
(the maximizer's Riccati equation escapes at t = 0.2) but the feedback game does.
"""

from __future__ import annotations

import pytest
import yaml
from scipy.integrate import solve_ivp

from gamespec.errors import UnsupportedFeature
from gamespec.loader import spec_from_dict
from gamespec.result import Status
from gamespec.solving import solve
from gamespec.summaries import outcome
from tests.games.test_honest_equilibria import NONZERO_SUM, SCALAR


def _spec(text: str, **game):
    data = yaml.safe_load(text)
    data["game"] = {**data["game"], "information": "feedback", **game}
    return spec_from_dict(data)


@pytest.mark.parametrize(("gamma2", "value"), [(1.2, 3 / 7), (0.8, 2 / 3)])
def test_feedback_saddle_of_the_scalar_game(gamma2, value) -> None:
    result = solve(_spec(SCALAR), parameters={"g2": gamma2})
    assert result.status is Status.OPTIMAL, result.message
    assert result.objective == pytest.approx(value, rel=1e-8)
    assert result.metrics["solution_concept"] == "feedback_saddle"
    assert result.metrics["information"] == "feedback"
    assert result.metrics["payoffs"] == pytest.approx({"pursuer": value, "evader": value}, rel=1e-8)
    assert result.metrics["saddle_gap"] < 1e-8
    assert result.states["x"][0] == pytest.approx(1.0)
    gain = result.metrics["gains"]["u"]
    P0 = 2 * value
    assert gain[0][0] == pytest.approx(P0, rel=1e-6), "u = -P(t) x for r = 1"
    assert ("solution", "feedback_saddle") in outcome(result)


def test_an_initial_state_written_as_an_expression_is_evaluated_at_each_solve() -> None:
    """``x(0) = 2·T`` (an expression of a parameter): the value is ``½ P(0) x₀²``, x₀ taken at the
    solve's parameter values (the value of the game is quadratic in the initial state)."""
    spec = _spec(SCALAR.replace("x: {initial: 1.0}", "x: {initial: 2*T}"))
    for T in (1.0, 0.5):
        result = solve(spec, parameters={"g2": 1.2, "T": T})
        assert result.status is Status.OPTIMAL, result.message
        P0 = 1 / (1 + (1 - 1 / 1.2) * T)
        assert result.objective == pytest.approx(0.5 * P0 * (2 * T) ** 2, rel=1e-8)


def test_the_open_loop_game_without_a_saddle_is_refused_where_the_feedback_one_is_solved() -> None:
    data = yaml.safe_load(SCALAR)
    data["problem"]["parameters"]["g2"] = 0.8
    assert solve(spec_from_dict(data)).status is Status.UNBOUNDED


def test_a_conjugate_point_of_the_feedback_game_is_unbounded_with_its_time() -> None:
    """γ² = 0.25, T = 1: ``1/P = 1 + (1 − 4)(1 − t)`` reaches 0 at t = 2/3."""
    result = solve(_spec(SCALAR), parameters={"g2": 0.25})
    assert result.status is Status.UNBOUNDED
    assert "t = 0.666667" in result.message


def test_nonzero_sum_feedback_nash_reports_both_payoffs() -> None:
    """Two minimizers ``ẋ = u1 + u2``, ``J_i = ½ s_i x(T)² + ½∫ u_i²``: with ``u_i = −p_i x`` and
    ``V_i = ½ p_i x²`` the scalar coupled equations are ``ṗ_i = p_i² + 2 p_i p_j``, ``p_i(T) = s_i``
    (derived by hand, integrated here with SciPy); ``J_i = ½ p_i(0)``. No player gains by its own
    reply."""
    result = solve(_spec(NONZERO_SUM))
    assert result.status is Status.OPTIMAL, result.message
    assert result.metrics["solution_concept"] == "feedback_nash"

    def backward(_, p):
        return [-(p[0] ** 2 + 2 * p[0] * p[1]), -(p[1] ** 2 + 2 * p[0] * p[1])]

    p0 = solve_ivp(backward, (0.0, 1.0), [1.0, 2.0], rtol=1e-12, atol=1e-14).y[:, -1]
    payoffs = result.metrics["payoffs"]
    assert payoffs == pytest.approx({"first": 0.5 * p0[0], "second": 0.5 * p0[1]}, rel=1e-8)
    assert result.objective == payoffs["first"]
    assert max(result.metrics["improvements"].values()) < 1e-8


def test_a_game_neither_method_takes_is_refused_naming_why() -> None:
    """Not LQ (a terminal constraint) and outside iterative LQ games (the constraint again)."""
    data = yaml.safe_load(SCALAR)
    data["problem"]["terminal_constraints"] = ["x_f >= 0.1"]
    with pytest.raises(UnsupportedFeature, match="terminal constraints"):
        solve(_spec(yaml.safe_dump(data)))


def test_feedback_and_a_receding_horizon_are_refused_at_load() -> None:
    from gamespec.errors import SpecError

    data = yaml.safe_load(SCALAR)
    data["game"]["information"] = "feedback"
    data["receding_horizon"] = {"step": 0.1, "time_limit": 1.0, "positions": {}}
    with pytest.raises(SpecError, match="feedback"):
        spec_from_dict(data)
