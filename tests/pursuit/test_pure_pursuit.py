"""Pure-pursuit evasion (§2.4.2–2.4.3): eq. 2.5, the suboptimal heading of eq. 2.27, the eq. 2.21 OCP."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import gamespec
from gamespec.pursuit import pure_pursuit as pp
from gamespec.pursuit import regions, verification
from gamespec.pursuit.ocp_generation import to_ocp
from gamespec.pursuit.simulation import Players, simulate_to_capture
from gamespec.studies.capturing_set import path_difference
from gamespec.symbolic.language import parse, symbol
from gamespec.transforms import engagement as transforms_engagement
from tests.conftest import PROBLEMS
from tests.pursuit.helpers import two_pursuers

TWO_ON_ONE = PROBLEMS / "ch2" / "pure_pursuit_two_on_one.yaml"
COLLINEAR = PROBLEMS / "ch2" / "pp_collinear_behind.yaml"


@given(st.floats(0.5, 3.0), st.floats(-np.pi, np.pi), st.floats(0.2, 0.8))
@settings(max_examples=15, deadline=None)
def test_eq_2_5_is_the_simulated_capture_time(r0: float, heading: float, v: float) -> None:
    """t_p = r_0 (u + v cos θ)/(u² − v²) against eq. 2.1 integrated with point-like capture."""
    players = Players(("P",), np.array([[0.0, 0.0]]), np.array([1.0]), ("pp",), np.array([r0, 0.0]), v, 1e-7)
    simulated = simulate_to_capture(players, heading).capture_time
    assert simulated == pytest.approx(pp.pursuit_time(r0, heading, 1.0, v), abs=1e-5)


@given(st.floats(-1.0, 6.0), st.floats(-4.0, 4.0))
@example(0.45, -0.4)
@example(0.9, 0.15)
@example(1.2, 0.4)
@settings(max_examples=30, deadline=None)
def test_suboptimal_heading_solves_eq_2_27_in_n_and_is_pure_evasion_in_d2(x: float, y: float) -> None:
    """N: equal eq. 2.5 times; D2: pure evasion from P1 (θ = 0); D1: pure evasion from P2 (θ = φ_2)."""
    players = two_pursuers((x, y), "pp")
    region = regions.classify("pp", [0, 0], np.array([x, y]), [1, 0], 1.0, 1.0, 0.5)
    choice = pp.suboptimal_heading(players)
    if region == "N":
        assert choice.times[0] == pytest.approx(choice.times[1], rel=1e-9)
    elif region == "D2":
        assert choice.heading == pytest.approx(0.0, abs=1e-12)
    else:
        assert region == "D1"
        assert choice.heading == pytest.approx(players.los_angles()[1], abs=1e-6)
        assert choice.capture_time == pytest.approx(players.distances()[1] / (1.0 - 0.5), rel=1e-9)


def test_optimal_capture_is_simultaneous_with_zero_hamiltonian_and_beats_the_suboptimal() -> None:
    """Theorem 2 and eq. 2.23 on the generated eq. 2.21 problem; the optimum is at least as late as
    the eq. 2.27 heading's capture, re-simulated with the true dynamics."""
    optimal = gamespec.solve(TWO_ON_ONE)
    suboptimal = gamespec.solve(TWO_ON_ONE, "analytic")
    assert optimal.status == gamespec.Status.OPTIMAL
    assert optimal.metrics["frame"] == "line_of_sight"
    assert optimal.metrics["capturing_set"] == ["P1", "P2"]
    assert optimal.metrics["simultaneous_capture_gap"] < 1e-6
    assert optimal.checks["hamiltonian_end_error"] < 1e-4
    assert optimal.checks["resimulated_capture_time_error"] < 1e-3
    assert suboptimal.status == gamespec.Status.FEASIBLE
    assert optimal.t_final >= suboptimal.t_final


def test_fixed_and_line_of_sight_frames_agree() -> None:
    """Eqs. 3.15–3.16 (inertial frame, 4 states) and eq. 2.21 (rotating frame, 3 states) are the same
    problem: same capture time and the same evader path. Both line-of-sight angles turn at up to
    v/ε near simultaneous capture, so the inertial form needs a stronger grading."""
    rotating = gamespec.solve(TWO_ON_ONE)
    fixed = gamespec.solve(gamespec.load(TWO_ON_ONE, ["frame=fixed", "method.grading=30"]))
    assert set(fixed.states) == {"r1", "phi1", "r2", "phi2"}
    assert fixed.checks["max_defect"] < 1e-6
    assert fixed.t_final == pytest.approx(rotating.t_final, rel=1e-6)
    assert path_difference(fixed, rotating) < 1e-3


def test_degenerate_pure_pursuit_is_pure_evasion_from_p1() -> None:
    """Prop. 1, first case: P2 in D2 → θ* = 0 and only P1 captures, at (d − ε)/(u1 − v)."""
    data = gamespec.load(TWO_ON_ONE).model_dump(mode="json")
    data["pursuers"][1]["position"] = [5.0, 3.0]
    spec = gamespec.spec_from_dict(data)
    assert regions.classify("pp", [0, 0], np.array([5.0, 3.0]), [1, 0], 1.0, 1.0, 0.5) == "D2"
    result = gamespec.solve(spec)
    assert result.metrics["capturing_set"] == ["P1"]
    assert result.t_final == pytest.approx((1.0 - 0.001) / 0.5, rel=1e-6)
    assert np.allclose(result.controls["theta"], 0.0, atol=1e-3)


def test_constant_inertial_heading_is_not_a_constant_theta() -> None:
    """The default guess is the eq. 2.27 heading simulated: constant θ_E, yet θ = θ_E − φ_1 varies,
    by as much as φ_1 turns (the fitted polynomial's range covers most of that turn)."""
    spec = gamespec.load(TWO_ON_ONE)
    ocp, inverse = to_ocp(spec)
    players = inverse.players
    traj = simulate_to_capture(players, inverse.guess_heading)
    los = traj.evader - traj.pursuers[:, 0]
    phi1 = np.unwrap(np.arctan2(los[:, 1], los[:, 0]))
    tau_symbol = symbol("tau")
    fitted = parse(ocp.guess.controls["theta"], {"tau": tau_symbol})
    theta = [float(fitted.subs(tau_symbol, t)) for t in np.linspace(0.0, 1.0, 201)]
    assert np.ptp(theta) > 0.9 * np.ptp(phi1) > 0.1


def test_a_wrong_nlp_optimum_is_not_reported_optimal(monkeypatch) -> None:
    """On a uniform grid the collinear engagement's NLP stops at a point whose Hamiltonian is not
    constant (eq. 2.23) and whose capture is earlier than the guess heading's: with no re-solve
    allowed it is reported feasible, with the failed check in the message."""
    monkeypatch.setattr(transforms_engagement, "RETRIES", 0)
    result = gamespec.solve(gamespec.load(COLLINEAR, ["method.grading=1"]))
    assert result.status == gamespec.Status.FEASIBLE
    assert "not verified optimal" in result.message


def test_collinear_pursuers_resolved_to_the_verified_optimum() -> None:
    """P1, E, P2 on a line: by symmetry heading ±π/2 is optimal, with the eq. 2.5 capture time of
    that constant heading (the analytic backend). On a uniform grid the first NLP solution fails
    the checks; the re-solves from the ranked constant headings find the optimum."""
    analytic = gamespec.solve(COLLINEAR, "analytic")
    for overrides in ([], ["method.grading=1"]):
        result = gamespec.solve(gamespec.load(COLLINEAR, overrides))
        assert result.status == gamespec.Status.OPTIMAL
        assert result.t_final == pytest.approx(analytic.t_final, rel=1e-4)
        assert result.checks["hamiltonian_variation"] < verification.HAMILTONIAN_TOL
        assert abs(result.metrics["initial_heading"]) == pytest.approx(np.pi / 2, abs=0.05)


def test_analytic_check_is_an_independent_resimulation() -> None:
    """The analytic backend's re-simulation is a second integration (not the solution itself), so
    its error is small but not zero by construction."""
    result = gamespec.solve(TWO_ON_ONE, "analytic")
    assert 0.0 < result.checks["resimulated_capture_time_error"] < 1e-6
