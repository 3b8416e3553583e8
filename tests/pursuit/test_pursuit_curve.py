"""The closed-form pursuit curve (eq. 2.5's integrals) against the true dynamics integrated (eq. 2.1)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gamespec.errors import UnsupportedFeature
from gamespec.pursuit.pure_pursuit import capture_times
from gamespec.pursuit.pursuit_curve import constant_heading_pursuit
from gamespec.pursuit.simulation import Players, simulate_to_capture


def _team(seed: int, n: int, eps: float = 1e-3) -> tuple[Players, float]:
    rng = np.random.default_rng(seed)
    players = Players(
        names=tuple(f"P{i}" for i in range(n)),
        positions=rng.uniform(-3, 3, (n, 2)),
        speeds=rng.uniform(1.0, 2.0, n),
        strategies=("pp",) * n,
        evader=rng.uniform(-1, 1, 2),
        v=float(rng.uniform(0.2, 0.95)),
        eps=eps,
    )
    return players, float(rng.uniform(-np.pi, np.pi))


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 3))
def test_closed_form_matches_the_integrated_dynamics(seed: int, n: int) -> None:
    """Capture time and positions agree with RK45 at rtol 1e-10 (its own error, with margin)."""
    players, heading = _team(seed, n)
    closed = constant_heading_pursuit(players, heading)
    integrated = simulate_to_capture(players, heading)
    assert closed.capture_time == pytest.approx(integrated.capture_time, rel=1e-8)
    scale = np.max(np.abs(integrated.pursuers))
    np.testing.assert_allclose(closed.pursuers, integrated.pursuers, atol=1e-7 * scale)
    np.testing.assert_allclose(closed.evader, integrated.evader, atol=1e-7 * scale)


@pytest.mark.parametrize("heading", [0.0, np.pi])
def test_chase_along_the_line_of_sight(heading: float) -> None:
    """Evader running straight away or head-on: r = r0 + (v cos α0 − u) t."""
    players = Players(("P",), np.zeros((1, 2)), np.array([1.0]), ("pp",), np.array([1.0, 0.0]), 0.5, 1e-3)
    expected = (1.0 - 1e-3) / (1.0 - 0.5 * np.cos(heading))
    assert constant_heading_pursuit(players, heading).capture_time == pytest.approx(expected, rel=1e-12)


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 3))
def test_point_capture_limit_is_eq_2_5(seed: int, n: int) -> None:
    """As ε → 0 the capture time tends to eq. 2.5's t_p = r0 (u + v cos θ)/(u² − v²), within ε/(u − v)."""
    players, heading = _team(seed, n, eps=1e-9)
    expected = capture_times(players, np.array([heading])).min()
    assert abs(constant_heading_pursuit(players, heading).capture_time - expected) <= 1e-9 / (1 - 0.95)


def test_needs_pure_pursuit() -> None:
    players, heading = _team(0, 2)
    with pytest.raises(UnsupportedFeature, match="pp"):
        constant_heading_pursuit(
            Players(
                players.names, players.positions, players.speeds, ("pp", "cb"), players.evader, 0.5, 1e-3
            ),
            heading,
        )
