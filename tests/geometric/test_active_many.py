"""The fast CB check batched over evaders (thesis §3.3.1) against the one-evader fast check."""

from __future__ import annotations

import numpy as np
from gamespec_geometric.active import active_in, capture_regions
from gamespec_geometric.active_many import MAX_BATCHED, active_cb_many
from hypothesis import given, settings
from hypothesis import strategies as st

SEEDS = st.integers(0, 2**32 - 1)


def _one_by_one(pursuers, evaders, u, v, candidates) -> np.ndarray:
    status = np.zeros(candidates.shape, dtype=bool)
    for j, members in enumerate(candidates):
        index = np.flatnonzero(members)
        if len(index):
            regions = capture_regions(pursuers[index], evaders[j], u[index], v[j], "cb")
            status[j, index] = active_in(regions, "fast")
    return status


def _ring(rng: np.random.Generator, n: int, centre: np.ndarray) -> np.ndarray:
    angles = rng.uniform(-np.pi, np.pi, n)
    return centre + rng.uniform(3, 8) * np.column_stack([np.cos(angles), np.sin(angles)])


@settings(max_examples=60, deadline=None)
@given(SEEDS, st.integers(1, 60), st.integers(1, 12), st.booleans(), st.booleans())
def test_batched_check_equals_one_evader_at_a_time(
    seed: int, n: int, m: int, heterogeneous: bool, encircled: bool
) -> None:
    """Random candidate sets, homogeneous or not, with some evaders encircled by co-circular pursuers
    of one speed: every row equals the one-evader check on the same candidates."""
    rng = np.random.default_rng(seed)
    evaders = rng.uniform(-10, 10, (m, 2))
    pursuers = rng.uniform(-12, 12, (n, 2))
    if encircled:
        pursuers = np.concatenate([pursuers, _ring(rng, n, evaders[0])])
    u = rng.uniform(1.0, 2.0, len(pursuers)) if heterogeneous else np.ones(len(pursuers))
    v = rng.uniform(0.1, 0.95, m)
    candidates = rng.uniform(size=(m, len(pursuers))) < rng.uniform(0.2, 1.0)
    np.testing.assert_array_equal(
        active_cb_many(pursuers, evaders, u, v, candidates), _one_by_one(pursuers, evaders, u, v, candidates)
    )


def test_evaders_with_many_survivors_go_to_the_lifted_hull() -> None:
    """An evader ringed by more than MAX_BATCHED pursuers of one speed (none holds another's disk)
    next to an evader with few: both rows equal the one-evader check."""
    rng = np.random.default_rng(3)
    evaders = np.array([[0.0, 0.0], [40.0, 0.0]])
    pursuers = np.concatenate([_ring(rng, 3 * MAX_BATCHED, evaders[0]), _ring(rng, 5, evaders[1])])
    u, v = np.ones(len(pursuers)), np.array([0.6, 0.5])
    candidates = np.ones((2, len(pursuers)), dtype=bool)
    status = active_cb_many(pursuers, evaders, u, v, candidates)
    assert status[0].sum() > MAX_BATCHED
    np.testing.assert_array_equal(status, _one_by_one(pursuers, evaders, u, v, candidates))
