"""Constant-bearing optimal evasion (§2.4.1, §3.2.1): closed form, theory, and the OCP agreeing."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import gamespec
from gamespec.pursuit import constant_bearing as cb
from gamespec.pursuit import regions
from gamespec.pursuit.report import CAPTURE_RTOL
from gamespec.pursuit.simulation import Players, simulate_to_capture
from tests.conftest import PROBLEMS
from tests.pursuit.helpers import apollonius_heading, two_pursuers

TWO_ON_ONE = PROBLEMS / "ch2" / "constant_bearing_two_on_one.yaml"
DEGENERATE = PROBLEMS / "ch2" / "constant_bearing_degenerate.yaml"
MPSE = PROBLEMS / "ch3" / "mpse_optimal_evasion_cb.yaml"
HEADINGS = np.linspace(-np.pi, np.pi, 20001)
BEAT_RTOL = 1e-6
"""Relative margin well above the plan/simulation agreement (1e-8) for 'later than'."""


@given(st.floats(0.5, 3.5), st.floats(-1.5, 1.5), st.sampled_from([0.8, 1.0, 1.5]))
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
def test_apollonius_heading_is_the_best_constant_heading(x: float, y: float, u2: float) -> None:
    """Fig. 2.7: in N (point capture) the farther Apollonius intersection maximizes min_i t_i (on the
    x-axis both intersections are equally far and either is optimal)."""
    assume(regions.classify("cb", [0, 0], np.array([x, y]), [1, 0], 1.0, u2, 0.5) == "N")
    players = two_pursuers((x, y), "cb", u2=u2, eps=1e-12)
    heading = apollonius_heading(players)
    best = cb.best_constant_heading(players)
    assert heading is not None
    times = cb.capture_times(players, np.array([heading]))[0]
    assert times.min() == pytest.approx(best.capture_time, rel=1e-9)
    assert times[0] == pytest.approx(times[1], rel=1e-9)
    assert best.capturing() == [0, 1]


def test_capture_times_match_the_true_dynamics() -> None:
    """(r_i(0) − ε)/−ṙ_i (eqs. 2.8–2.9) against eq. 2.1 integrated with each CB pursuer alone."""
    players = Players.from_spec(gamespec.load(MPSE))
    for heading in (-2.0, 0.3, 2.5):
        times = cb.capture_times(players, np.array([heading]))[0]
        simulated = [simulate_to_capture(players.subset([i]), heading).capture_time for i in range(5)]
        assert np.allclose(times, simulated, rtol=1e-8)


@pytest.mark.parametrize("path", [TWO_ON_ONE, DEGENERATE, MPSE])
def test_plan_satisfies_the_minimum_principle(path) -> None:
    """With the program's costates, H (eq. 3.6) is ≥ 0 for every heading and 0 on the headings used
    (eq. 3.9), and λ_i = 0 for the pursuers outside P* (Prop. 5)."""
    players = Players.from_spec(gamespec.load(path))
    plan = cb.optimal_evasion(players)
    assert cb.hamiltonian(players, plan.costates, HEADINGS).min() > -1e-5
    assert np.allclose(cb.hamiltonian(players, plan.costates, plan.headings), 0.0, atol=1e-5)
    r_final = (
        players.distances()
        + cb.closing_rate(plan.headings[:, None], players.los_angles(), players.speeds, players.v).T
        @ plan.durations
    )
    outside = r_final > players.eps * (1 + CAPTURE_RTOL)
    assert np.all(plan.costates[outside] == 0.0)
    assert np.all(plan.costates[~outside] < 0.0)


def test_non_degenerate_two_on_one_is_simultaneous_capture_with_constant_heading() -> None:
    """Theorem 1: P2 in N → one constant heading, and both pursuers capture at t_c."""
    result = gamespec.solve(TWO_ON_ONE, "analytic")
    assert result.metrics["region"] == "N"
    assert len(result.metrics["headings"]) == 1
    assert result.metrics["capturing_set"] == ["P1", "P2"]
    assert result.metrics["simultaneous_capture_gap"] < 1e-7


def test_degenerate_two_on_one_is_pure_evasion_from_p1() -> None:
    """P2 in D2: θ_E = φ_1 and t_c = (d − ε)/(u1 − v) (eq. 2.2 with the capture radius)."""
    result = gamespec.solve(DEGENERATE, "analytic")
    assert result.metrics["region"] == "D2"
    assert result.metrics["headings"] == [pytest.approx(0.0, abs=1e-9)]
    assert result.metrics["capturing_set"] == ["P1"]
    assert result.t_final == pytest.approx((1.0 - 0.001) / (1.0 - 0.5), rel=1e-12)


@pytest.mark.parametrize("path", [TWO_ON_ONE, DEGENERATE])
def test_ocp_agrees_with_the_closed_form(path) -> None:
    """The generated eq. 2.8 OCP on CasADi: same capture time, same constant heading, H = 0."""
    exact = gamespec.solve(path, "analytic")
    ocp = gamespec.solve(path)
    assert ocp.status == gamespec.Status.OPTIMAL
    assert ocp.t_final == pytest.approx(exact.t_final, abs=1e-6)
    assert np.allclose(ocp.controls["theta_E"], exact.metrics["headings"][0], atol=1e-4)
    assert ocp.metrics["capturing_set"] == exact.metrics["capturing_set"]
    assert ocp.checks["hamiltonian_end_error"] < 1e-4
    assert ocp.checks["resimulated_capture_time_error"] < 1e-6


def test_several_pursuers_can_beat_every_constant_heading() -> None:
    """The disagreement with eq. 2.15's 'θ_E constant': with five pursuers the optimal plan uses two
    headings, and the true dynamics under it capture later than under the best constant heading."""
    players = Players.from_spec(gamespec.load(MPSE))
    plan = cb.optimal_evasion(players)
    constant = cb.best_constant_heading(players)
    simulated = simulate_to_capture(players, plan.law()).capture_time
    assert len(plan.headings) >= 2
    assert simulated == pytest.approx(plan.capture_time, rel=1e-8)
    assert simulated > constant.capture_time * (1 + BEAT_RTOL)


@given(st.floats(0.5, 3.5), st.floats(-1.5, 1.5), st.sampled_from([0.6, 1.0, 2.0]))
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
def test_two_pursuers_in_n_one_heading_and_simultaneous_capture(x: float, y: float, u2: float) -> None:
    """Theorem 1 over N: the exact optimum (the linear program) uses one heading, and both pursuers
    capture at t_c; the thesis's constant heading is optimal here."""
    assume(regions.classify("cb", [0, 0], np.array([x, y]), [1, 0], 1.0, u2, 0.5) == "N")
    players = two_pursuers((x, y), "cb", u2=u2, eps=1e-9)
    plan = cb.optimal_evasion(players)
    times = cb.capture_times(players, plan.headings)[0]
    assert len(plan.headings) == 1
    assert times[0] == pytest.approx(times[1], rel=1e-6)
    assert plan.capture_time == pytest.approx(cb.best_constant_heading(players).capture_time, rel=1e-9)
