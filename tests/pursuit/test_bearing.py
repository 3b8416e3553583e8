"""Line of sight (eq. 3.17), constant-bearing headings (eq. 3.3), the Apollonius circle in §2.3.1's
frame (its locus property is checked in tests/geometric/test_apollonius.py)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from gamespec.pursuit.apollonius import apollonius_circles
from gamespec.pursuit.bearing import constant_bearing_headings, line_of_sight_angles

SEEDS = st.integers(0, 2**32 - 1)


def _team(seed: int, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    rng = np.random.default_rng(seed)
    return rng.uniform(-5, 5, (n, 2)), rng.uniform(-5, 5, 2), rng.uniform(1.0, 2.0, n), 0.9


@settings(max_examples=30, deadline=None)
@given(SEEDS, st.integers(1, 8), st.floats(-np.pi, np.pi))
def test_constant_bearing_keeps_the_line_of_sight_direction(seed: int, n: int, heading: float) -> None:
    """Eq. 3.3: the evader's velocity relative to each pursuer lies along the line of sight and
    closes the distance."""
    pursuers, evader, u, v = _team(seed, n)
    los = line_of_sight_angles(pursuers, evader)
    sight = evader - pursuers
    np.testing.assert_allclose(los, np.arctan2(sight[:, 1], sight[:, 0]))
    theta = constant_bearing_headings(los, u, v, heading)
    relative = v * np.array([np.cos(heading), np.sin(heading)]) - u[:, None] * np.column_stack(
        [np.cos(theta), np.sin(theta)]
    )
    cross = sight[:, 0] * relative[:, 1] - sight[:, 1] * relative[:, 0]
    np.testing.assert_allclose(cross, 0.0, atol=1e-9)
    assert np.all(np.sum(sight * relative, axis=1) < 0)


def test_pursuer_at_rest_keeps_the_line_of_sight() -> None:
    los = np.array([0.3, -1.2])
    np.testing.assert_array_equal(constant_bearing_headings(los, np.array([0.0, 0.0]), 0.5, 2.0), los)


def test_apollonius_circle_in_the_frame_of_section_2_3_1() -> None:
    """P1 at the origin, E at (d, 0): centre (u² d/(u² − v²), 0), radius u v d/(u² − v²)."""
    d, u, v = 2.0, 1.0, 0.6
    circles = apollonius_circles(np.zeros((1, 2)), np.array([d, 0.0]), np.array([u]), v)
    np.testing.assert_allclose(circles.centers[0], [u**2 * d / (u**2 - v**2), 0.0])
    np.testing.assert_allclose(circles.radii[0], u * v * d / (u**2 - v**2))
