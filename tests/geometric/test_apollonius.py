"""Apollonius circles and curves (thesis §3.3): the defining ratio, eq. 3.24, Lemma 1."""

from __future__ import annotations

import numpy as np
from gamespec_geometric.apollonius import (
    cb_reach,
    circle_radial_distance,
    pp_curve_radius,
    refined_pp_polygons,
    refined_pp_radius,
    refined_pp_reach,
)
from gamespec_geometric.simulation import simulate
from hypothesis import given, settings
from hypothesis import strategies as st

from gamespec.loader import spec_from_dict
from gamespec.pursuit.apollonius import apollonius_circles
from gamespec.pursuit.bearing import line_of_sight_angles
from gamespec.pursuit.pure_pursuit import pursuit_time
from tests.geometric.helpers import random_team

SEEDS = st.integers(0, 2**32 - 1)
ANGLES = np.linspace(-np.pi, np.pi, 721)


@settings(max_examples=40, deadline=None)
@given(SEEDS, st.integers(1, 12), st.booleans())
def test_circle_is_the_locus_of_equal_arrival(seed: int, n: int, heterogeneous: bool) -> None:
    """Every point of circle i is reached as soon by the evader as by pursuer i: |X-e|/v = |X-p_i|/u_i."""
    pursuers, evader, u, v = random_team(seed, n, heterogeneous)
    circles = apollonius_circles(pursuers, evader, u, v)
    points = circles.centers[:, None, :] + circles.radii[:, None, None] * np.stack(
        [np.cos(ANGLES), np.sin(ANGLES)], axis=-1
    )
    evader_time = np.linalg.norm(points - evader, axis=2) / v
    pursuer_time = np.linalg.norm(points - pursuers[:, None, :], axis=2) / u[:, None]
    np.testing.assert_allclose(evader_time, pursuer_time, rtol=1e-9)
    head_on = np.linalg.norm(pursuers - evader, axis=1) * v / (u + v)
    np.testing.assert_allclose(np.linalg.norm(circles.closest_points - evader, axis=1), head_on, rtol=1e-12)
    np.testing.assert_allclose(
        np.linalg.norm(circles.closest_points - circles.centers, axis=1), circles.radii
    )


@settings(max_examples=40, deadline=None)
@given(SEEDS, st.integers(1, 12), st.booleans())
def test_lemma_1_circle_inside_curve_inside_refined_curve(seed: int, n: int, heterogeneous: bool) -> None:
    """Lemma 1: the Apollonius circle lies inside the PP curve, which lies inside its convex hull."""
    pursuers, evader, u, v = random_team(seed, n, heterogeneous)
    circle = circle_radial_distance(apollonius_circles(pursuers, evader, u, v), evader, ANGLES)
    sight = ANGLES[None, :] - line_of_sight_angles(pursuers, evader)[:, None]
    distance = np.linalg.norm(pursuers - evader, axis=1)[:, None]
    curve = pp_curve_radius(distance, sight, u[:, None], v)
    refined = refined_pp_radius(distance, sight, u[:, None], v)
    assert np.all(circle <= curve * (1 + 1e-9))
    assert np.all(curve <= refined * (1 + 1e-12))


@settings(max_examples=40, deadline=None)
@given(SEEDS, st.integers(1, 12), st.booleans())
def test_refined_polygons_are_convex_and_on_the_refined_curve(seed: int, n: int, heterogeneous: bool) -> None:
    """The inscribed polygons turn left at every vertex and their vertices lie on the refined curve."""
    pursuers, evader, u, v = random_team(seed, n, heterogeneous)
    polygons = refined_pp_polygons(pursuers, evader, u, v, samples=48)
    edges = np.roll(polygons, -1, axis=1) - polygons
    following = np.roll(edges, -1, axis=1)
    turns = edges[..., 0] * following[..., 1] - edges[..., 1] * following[..., 0]
    assert np.all(turns > 0)
    offset = polygons - evader
    sight = np.arctan2(offset[..., 1], offset[..., 0]) - line_of_sight_angles(pursuers, evader)[:, None]
    distance = np.linalg.norm(pursuers - evader, axis=1)[:, None]
    np.testing.assert_allclose(
        np.linalg.norm(offset, axis=-1), refined_pp_radius(distance, sight, u[:, None], v), rtol=1e-9
    )


def _duel(strategy: str, heading: float, radius: float, step: float) -> tuple[float, float]:
    """One pursuer at the origin, a non-maneuvering evader at (4, 1): capture time and LoS heading."""
    spec = spec_from_dict(
        {
            "kind": "pursuit_scenario",
            "pursuers": {"positions": [[0.0, 0.0]], "speed": 1.0, "strategy": strategy},
            "evaders": {
                "positions": [[4.0, 1.0]],
                "speed": 0.6,
                "strategy": {"type": "fixed", "heading": heading},
            },
            "capture_radius": radius,
            "time_step": step,
            "horizon": 40.0,
        }
    )
    return simulate(spec).capture_times[0], heading - np.arctan2(1.0, 4.0)


def test_eq_3_24_pure_pursuit_capture_time_matches_simulation() -> None:
    """Pure pursuit of a non-maneuvering evader ends at t_f of eq. 3.24, within the capture radius' slack."""
    radius = step = 5e-3
    for heading in (0.3, 2.0, -2.8):
        captured, sight = _duel("pp", heading, radius, step)
        exact = pursuit_time(np.hypot(4.0, 1.0), sight, 1.0, 0.6)
        assert exact - radius / (1.0 - 0.6) - 4 * step <= captured <= exact + 4 * step


def test_constant_bearing_captures_on_the_apollonius_circle() -> None:
    """CB against a non-maneuvering evader meets it where its heading crosses the Apollonius circle."""
    radius = 1e-3
    for heading in (0.3, 2.0, -2.8):
        captured, _ = _duel("cb", heading, radius, step=0.01)
        circles = apollonius_circles(np.zeros((1, 2)), np.array([4.0, 1.0]), np.ones(1), 0.6)
        exact = circle_radial_distance(circles, np.array([4.0, 1.0]), np.array([heading]))[0, 0] / 0.6
        assert exact - radius / (1.0 - 0.6) <= captured <= exact + 1e-9


@settings(max_examples=40, deadline=None)
@given(SEEDS, st.integers(1, 12), st.booleans())
def test_reach_bounds_are_the_nearest_and_farthest_points(seed: int, n: int, heterogeneous: bool) -> None:
    """The closed-form reach of circles and refined curves matches their sampled radial distances."""
    pursuers, evader, u, v = random_team(seed, n, heterogeneous)
    distance = np.linalg.norm(pursuers - evader, axis=1)
    circle = circle_radial_distance(apollonius_circles(pursuers, evader, u, v), evader, ANGLES)
    near, far = cb_reach(distance, u, v)
    np.testing.assert_allclose([circle.min(axis=1), circle.max(axis=1)], [near, far], rtol=1e-4)
    refined = refined_pp_radius(distance[:, None], ANGLES[None, :], u[:, None], v)
    near, far = refined_pp_reach(distance, u, v)
    np.testing.assert_allclose([refined.min(axis=1), refined.max(axis=1)], [near, far], rtol=1e-4)
