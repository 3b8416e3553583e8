"""Scenarios whose pursuers use their own strategies (a list of cb / pp, one per pursuer)."""

from __future__ import annotations

import numpy as np
import pytest
from gamespec_geometric.active import active_in, capture_regions
from gamespec_geometric.apollonius import circle_polygons
from gamespec_geometric.simulation import simulate

import gamespec
from gamespec.loader import spec_from_dict
from gamespec.pursuit.apollonius import apollonius_circles
from tests.geometric.helpers import random_team
from tests.geometric.test_scenario import _scenario, capture_time_bound


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


@pytest.mark.parametrize("strategy", ["cb", "pp"])
def test_a_list_of_one_strategy_is_that_team(strategy: str) -> None:
    data = _scenario(3, 4, 2, heterogeneous=True, strategy=strategy)
    team = simulate(spec_from_dict(data))
    data["pursuers"]["strategy"] = [strategy] * 4
    listed = simulate(spec_from_dict(data))
    assert np.array_equal(team.pursuers, listed.pursuers) and np.array_equal(
        team.allocation, listed.allocation
    )


def test_each_pursuer_moves_by_its_own_law() -> None:
    """Against a fixed-heading evader, the CB pursuer flies a straight line while it chases (eq. 3.3
    holds a constant heading), and the PP pursuer's every step points along its line of sight."""
    data = {
        "kind": "pursuit_scenario",
        "pursuers": {"positions": [[-4.0, -3.0], [4.0, -3.0]], "speed": 1.0, "strategy": ["cb", "pp"]},
        "evaders": {"positions": [[0.0, 0.0]], "speed": 0.5, "strategy": {"type": "fixed", "heading": 1.2}},
        "capture_radius": 0.05,
        "time_step": 0.01,
        "horizon": 30.0,
    }
    result = gamespec.solve(spec_from_dict(data))
    assert result.status is gamespec.Status.SIMULATED and result.metrics["pursuer_strategies"] == ["cb", "pp"]
    pursuers, evader = result.states["pursuers"], result.states["evaders"][:, 0]
    steps = np.diff(pursuers, axis=0)
    for i, strategy in enumerate(["cb", "pp"]):
        k = np.flatnonzero(result.arrays["allocation"][:-1, i] == 0)
        assert k.size > 10
        direction = steps[k, i] / np.linalg.norm(steps[k, i], axis=1, keepdims=True)
        if strategy == "cb":
            assert np.ptp(np.arctan2(direction[:, 1], direction[:, 0])) < 1e-9
        else:
            los = evader[k] - pursuers[k, i]
            los /= np.linalg.norm(los, axis=1, keepdims=True)
            assert np.max(np.abs(_cross(direction, los))) < 1e-9 and np.all(
                np.sum(direction * los, axis=1) > 0
            )


def test_a_mixed_team_captures_every_evader() -> None:
    data = _scenario(11, 6, 3, heterogeneous=True)
    data["pursuers"]["strategy"] = ["cb", "pp"] * 3
    data["horizon"] = capture_time_bound(data) + 1.0
    result = gamespec.solve(spec_from_dict(data))
    assert all(t is not None for t in result.metrics["capture_times"]), result.message


@pytest.mark.parametrize("seed", range(6))
def test_mixed_active_sets_fast_and_reference_agree(seed: int) -> None:
    pursuers, evader, speeds, v = random_team(seed, 7, heterogeneous=True)
    kinds = np.where(np.arange(7) % 2 == 0, "cb", "pp")
    regions = capture_regions(pursuers, evader, speeds, v, kinds, samples=64)
    assert regions.strategy == "mixed"
    assert np.array_equal(active_in(regions, "fast"), active_in(regions, "reference"))


def test_circle_polygons_are_inscribed_and_keep_their_distance() -> None:
    pursuers, evader, speeds, v = random_team(5, 5, heterogeneous=True)
    circles = apollonius_circles(pursuers, evader, speeds, v)
    samples = 48
    polygons = circle_polygons(circles.centers, circles.radii, evader, samples)
    on_circle = np.linalg.norm(polygons - circles.centers[:, None, :], axis=2)
    assert np.allclose(on_circle, circles.radii[:, None], rtol=1e-12)
    nearest = circles.radii - np.linalg.norm(circles.centers - evader, axis=1)
    a, b = polygons - evader, np.roll(polygons, -1, axis=1) - evader
    edge_distance = np.abs(_cross(a, b)) / np.linalg.norm(b - a, axis=2)
    assert np.all(edge_distance >= nearest[:, None] * np.cos(np.pi / samples) * (1 - 1e-12))


def test_a_strategy_list_of_the_wrong_length_names_the_field() -> None:
    data = _scenario(0, 3, 1, heterogeneous=False)
    data["pursuers"]["strategy"] = ["cb", "pp"]
    with pytest.raises(gamespec.SpecError, match=r"pursuers\.strategy"):
        spec_from_dict(data)
