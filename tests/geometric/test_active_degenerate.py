"""The fast CB check on degenerate teams: co-circular, collinear, coincident and near-co-circular
pursuers of one speed, whose lifted dual points span no volume (thesis §3.3.1, Algorithm 1)."""

from __future__ import annotations

import numpy as np
import pytest
from gamespec_geometric import active, active_pursuers
from gamespec_geometric.apollonius import circle_radial_distance
from hypothesis import given, settings
from hypothesis import strategies as st

from gamespec.pursuit.apollonius import apollonius_circles

SEEDS = st.integers(0, 2**32 - 1)


def _on_circle(rng: np.random.Generator, n: int, centre: np.ndarray, radius: float) -> np.ndarray:
    angles = rng.uniform(-np.pi, np.pi, n)
    return centre + radius * np.column_stack([np.cos(angles), np.sin(angles)])


def _team(seed: int, n: int, layout: str) -> tuple[np.ndarray, np.ndarray, float]:
    rng = np.random.default_rng(seed)
    if layout == "centred circle":
        return _on_circle(rng, n, np.zeros(2), rng.uniform(2, 10)), np.zeros(2), rng.uniform(0.1, 0.95)
    if layout == "circle":
        centre = rng.uniform(-3, 3, 2)
        pursuers = _on_circle(rng, n, centre, rng.uniform(4, 10))
        return pursuers, centre + rng.uniform(-2, 2, 2), rng.uniform(0.1, 0.95)
    if layout == "jittered circle":
        pursuers = _on_circle(rng, n, np.zeros(2), 6.0) + 1e-9 * rng.standard_normal((n, 2))
        return pursuers, np.zeros(2), rng.uniform(0.1, 0.95)
    heading = rng.uniform(-np.pi, np.pi)
    along = rng.uniform(-10, 10, n)[:, None] * np.array([np.cos(heading), np.sin(heading)])
    return rng.uniform(-3, 3, 2) + along, rng.uniform(-3, 3, 2), rng.uniform(0.1, 0.95)


@settings(max_examples=80, deadline=None)
@given(SEEDS, st.integers(1, 40), st.sampled_from(["centred circle", "circle", "jittered circle", "line"]))
def test_degenerate_teams_match_aapc(seed: int, n: int, layout: str) -> None:
    """Co-circular, collinear and 1e-9-jittered teams of one speed: the fast check equals AAPC."""
    pursuers, evader, v = _team(seed, n, layout)
    fast = active_pursuers(pursuers, evader, 1.0, v, "cb")
    np.testing.assert_array_equal(fast, active_pursuers(pursuers, evader, 1.0, v, "cb", method="reference"))


@settings(max_examples=30, deadline=None)
@given(SEEDS, st.integers(1, 20), st.integers(1, 10))
def test_coincident_pursuers_share_one_status(seed: int, n: int, copies: int) -> None:
    """Coincident pursuers trace one circle, so they share its status whatever their order: that of
    the circle in the team without the copies (AAPC, which cannot see coincident circles)."""
    rng = np.random.default_rng(seed)
    pursuers, evader, v = _team(seed, n, "circle")
    repeated = rng.integers(0, n, copies)
    team = np.concatenate([pursuers, pursuers[repeated]])
    order = rng.permutation(len(team))
    status = active_pursuers(team[order], evader, 1.0, v, "cb")[np.argsort(order)]
    distinct = active_pursuers(pursuers, evader, 1.0, v, "cb", method="reference")
    np.testing.assert_array_equal(status, np.concatenate([distinct, distinct[repeated]]))


def _ray_cast(pursuers: np.ndarray, evader: np.ndarray, v: float, rays: int) -> np.ndarray:
    """Pursuers whose circle is the first one met along at least one of ``rays`` evenly spaced rays."""
    circles = apollonius_circles(pursuers, evader, np.ones(len(pursuers)), v)
    seen = np.zeros(len(pursuers), dtype=bool)
    for directions in np.array_split(np.linspace(-np.pi, np.pi, rays, endpoint=False), rays // 1000 + 1):
        seen[np.argmin(circle_radial_distance(circles, evader, directions), axis=0)] = True
    return seen


@pytest.mark.parametrize("jitter", [0.0, 1e-9])
def test_thousand_co_circular_pursuers_match_a_ray_cast(jitter: float) -> None:
    """1000 pursuers on a circle around the evader, at least pi / n apart: each owns the wedge between
    the bisectors to its neighbours, so rays pi / (8 n) apart meet every arc."""
    n = 1000
    rng = np.random.default_rng(7)
    angles = 2 * np.pi * (np.arange(n) + rng.uniform(0, 0.5, n)) / n
    pursuers = 8.0 * np.column_stack([np.cos(angles), np.sin(angles)])
    pursuers = pursuers[rng.permutation(n)] + jitter * rng.standard_normal((n, 2))
    status = active_pursuers(pursuers, np.zeros(2), 1.0, 0.6, "cb")
    np.testing.assert_array_equal(status, _ray_cast(pursuers, np.zeros(2), 0.6, 16 * n))


@pytest.mark.parametrize("layout", ["centred circle", "circle", "line"])
@pytest.mark.parametrize("n", [1, 2, 3, 50])
def test_default_path_never_runs_aapc(monkeypatch, layout: str, n: int) -> None:
    """Neither degenerate teams nor fewer than four candidates fall back to the O(n**3) AAPC."""
    pursuers, evader, v = _team(n, n, layout)

    def forbidden(circles):
        raise AssertionError("AAPC called in the default path")

    monkeypatch.setattr(active, "aapc", forbidden)
    assert active_pursuers(pursuers, evader, 1.0, v, "cb").any()
