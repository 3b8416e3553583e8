"""Regions of non-degeneracy (§2.3) against simulations of pure evasion with the true dynamics."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gamespec.pursuit import regions
from gamespec.pursuit.regions import Frame
from gamespec.pursuit.simulation import simulate_to_capture
from tests.pursuit.helpers import two_pursuers

MARGIN = 0.02
"""Relative gap between the two capture times below which a point is too close to call."""


def _capture_times(players, heading: float, rtol: float = 1e-10) -> np.ndarray:
    """Capture time of each pursuer alone against a constant evader heading (true dynamics)."""
    return np.array(
        [simulate_to_capture(players.subset([i]), heading, rtol=rtol).capture_time for i in (0, 1)]
    )


def _region_by_simulation(p2, strategy: str, u2: float) -> str | None:
    """D2 when pure evasion from P1 ends with P1 first, D1 when pure evasion from P2 ends with P2
    first, N when neither; None when a race is too close to call."""
    players = two_pursuers(p2, strategy, u2=u2, eps=1e-4)
    phi = players.los_angles()
    from_p1, from_p2 = (_capture_times(players, phi[k], rtol=1e-6) for k in (0, 1))
    for times in (from_p1, from_p2):
        if abs(times[0] - times[1]) < MARGIN * times.min():
            return None
    if from_p1[0] <= from_p1[1]:
        return "D2"
    return "D1" if from_p2[1] < from_p2[0] else "N"


@pytest.mark.parametrize("strategy", ["cb", "pp"])
@pytest.mark.parametrize("u2", [1.0, 1.5])
def test_classification_agrees_with_simulated_pure_evasion(strategy: str, u2: float) -> None:
    xs, ys = np.linspace(-0.5, 5.0, 7), np.linspace(-3.0, 3.0, 7)
    seen = set()
    for x in xs:
        for y in ys:
            expected = _region_by_simulation((x, y), strategy, u2)
            if expected is None or np.hypot(x - 1.0, y) < 0.05:
                continue
            got = str(regions.classify(strategy, [0, 0], np.array([x, y]), [1, 0], 1.0, u2, 0.5))
            assert got == expected, (x, y)
            seen.add(got)
    assert seen == {"D1", "D2", "N"}


@given(st.floats(-np.pi, np.pi))
@settings(max_examples=10, deadline=None)
def test_points_of_c2_and_f_give_simultaneous_capture_under_pure_evasion_from_p2(theta: float) -> None:
    """C2 (eq. 2.4) and F (eq. 2.6): P2 there, fleeing P2 ends with both pursuers at once."""
    centre, radius = regions.cb_circle_c2(1.0, 1.0, 1.0, 0.5)
    on_c2 = centre + radius * np.array([np.cos(theta), np.sin(theta)])
    on_f = regions.pp_curve_f(1.0, 1.0, 1.0, 0.5, np.array([theta]))[0]
    for strategy, point in (("cb", on_c2), ("pp", on_f)):
        players = two_pursuers(point, strategy, eps=1e-7)
        times = _capture_times(players, players.los_angles()[1])
        assert times[0] == pytest.approx(times[1], rel=1e-4)


@given(st.floats(-np.pi, np.pi))
@settings(max_examples=10, deadline=None)
def test_points_of_c1_and_e_capture_at_the_pure_evasion_time(theta: float) -> None:
    """C1 and E are t_f-isochrones (eq. 2.2): P2 there catches the evader fleeing P1 at t_f."""
    tf = regions.pure_evasion_time(1.0, 1.0, 0.5)
    centre, radius = regions.cb_circle_c1(1.0, 1.0, 1.0, 0.5)
    on_c1 = centre + radius * np.array([np.cos(theta), np.sin(theta)])
    focus, other, total = regions.pp_ellipse_foci(1.0, 1.0, 1.0, 0.5)
    a, c = total / 2, (other[0] - focus[0]) / 2
    on_e = (focus + other) / 2 + np.array([a * np.cos(theta), np.sqrt(a**2 - c**2) * np.sin(theta)])
    for strategy, point in (("cb", on_c1), ("pp", on_e)):
        players = two_pursuers(point, strategy, eps=1e-7)
        assert _capture_times(players, 0.0)[1] == pytest.approx(tf, rel=1e-4)


@given(
    st.tuples(st.floats(-5, 5), st.floats(-5, 5)),
    st.tuples(st.floats(-5, 5), st.floats(-5, 5)),
    st.lists(st.tuples(st.floats(-5, 5), st.floats(-5, 5)), min_size=1, max_size=4),
)
def test_frame_round_trip_puts_p1_at_origin_and_e_on_the_x_axis(p1, e, points) -> None:
    if np.hypot(e[0] - p1[0], e[1] - p1[1]) < 1e-3:
        return
    frame = Frame.of(np.array(p1), np.array(e))
    assert np.allclose(frame.to_local(np.array(p1)), [0, 0], atol=1e-9)
    assert np.allclose(frame.to_local(np.array(e)), [frame.d, 0], atol=1e-9)
    pts = np.array(points)
    assert np.allclose(frame.to_world(frame.to_local(pts)), pts, atol=1e-9)


def test_boundary_polylines_lie_on_their_curves() -> None:
    """The plotted polylines satisfy the defining equations (world frame, P1 and E anywhere)."""
    p1, e = np.array([0.5, -1.0]), np.array([2.0, 1.0])
    frame = Frame.of(p1, e)
    cb = regions.boundary_curves("cb", p1, e, 1.0, 1.2, 0.5)
    pp = regions.boundary_curves("pp", p1, e, 1.0, 1.2, 0.5)
    for name, circle in (("C1", regions.cb_circle_c1), ("C2", regions.cb_circle_c2)):
        centre, radius = circle(frame.d, 1.0, 1.2, 0.5)
        assert np.allclose(np.linalg.norm(frame.to_local(cb[name]) - centre, axis=1), radius)
    focus, other, total = regions.pp_ellipse_foci(frame.d, 1.0, 1.2, 0.5)
    local = frame.to_local(pp["E"])
    assert np.allclose(np.linalg.norm(local - focus, axis=1) + np.linalg.norm(local - other, axis=1), total)


def test_faster_p2_enlarges_the_non_degenerate_region() -> None:
    """Fig. 2.3: N grows with u2 (checked on a grid for CB and PP)."""
    grid = np.stack(np.meshgrid(np.linspace(-4, 6, 60), np.linspace(-5, 5, 60)), axis=-1)
    for strategy in ("cb", "pp"):
        sizes = [
            np.sum(regions.classify(strategy, [0, 0], grid, [1, 0], 1.0, u2, 0.5) == "N")
            for u2 in (0.6, 1.0, 1.5)
        ]
        assert sizes[0] < sizes[1] < sizes[2]


def test_pp_regions_nest_inside_cb_regions() -> None:
    """§2.3.2: E lies inside C1 and F contains C2, so N is smaller for PP than for CB."""
    grid = np.stack(np.meshgrid(np.linspace(-4, 6, 80), np.linspace(-5, 5, 80)), axis=-1)
    cb = regions.classify("cb", [0, 0], grid, [1, 0], 1.0, 1.0, 0.5)
    pp = regions.classify("pp", [0, 0], grid, [1, 0], 1.0, 1.0, 0.5)
    assert not np.any((pp == "N") & (cb != "N"))
    assert np.all(pp[cb == "D1"] == "D1")
