"""Active and redundant pursuers (thesis §3.3.1): the fast checks against AAPC, Lemmas 2 and 7."""

from __future__ import annotations

import numpy as np
import pytest
from gamespec_geometric import active_pursuers
from gamespec_geometric.apollonius import refined_pp_radius
from hypothesis import given, settings
from hypothesis import strategies as st

from gamespec.errors import SpecError
from tests.geometric.helpers import random_team

SEEDS = st.integers(0, 2**32 - 1)


@settings(max_examples=60, deadline=None)
@given(SEEDS, st.integers(1, 40), st.booleans())
def test_fast_cb_check_equals_aapc(seed: int, n: int, heterogeneous: bool) -> None:
    """The lifted convex-hull check and Algorithm 1 (AAPC) find the same active pursuers."""
    team = random_team(seed, n, heterogeneous)
    fast = active_pursuers(*team, strategy="cb", method="fast")
    np.testing.assert_array_equal(fast, active_pursuers(*team, strategy="cb", method="reference"))


@settings(max_examples=40, deadline=None)
@given(SEEDS, st.integers(1, 15), st.booleans())
def test_fast_pp_check_equals_edge_clipping(seed: int, n: int, heterogeneous: bool) -> None:
    """On the refined PP polygons, the dual-hull check and clipping every edge agree."""
    team = random_team(seed, n, heterogeneous)
    fast = active_pursuers(*team, strategy="pp", method="fast", samples=32)
    reference = active_pursuers(*team, strategy="pp", method="reference", samples=32)
    np.testing.assert_array_equal(fast, reference)


@settings(max_examples=60, deadline=None)
@given(SEEDS, st.integers(1, 60), st.booleans(), st.sampled_from(["fast", "reference"]))
def test_lemmas_2_and_7_soonest_pursuer_is_active(
    seed: int, n: int, heterogeneous: bool, method: str
) -> None:
    """Lemma 2 (Lemma 7 for heterogeneous teams): argmin |p_i - e| / (u_i + v) is always active (CB)."""
    pursuers, evader, u, v = random_team(seed, n, heterogeneous)
    status = active_pursuers(pursuers, evader, u, v, "cb", method=method)
    assert status[np.argmin(np.linalg.norm(pursuers - evader, axis=1) / (u + v))]


@settings(max_examples=40, deadline=None)
@given(SEEDS, st.integers(1, 40), st.booleans())
def test_pp_pursuer_with_the_nearest_refined_curve_is_active(seed: int, n: int, heterogeneous: bool) -> None:
    """The refined curve nearest to the evader is part of the Apollonius boundary (PP analogue of Lemma 2)."""
    pursuers, evader, u, v = random_team(seed, n, heterogeneous)
    distance = np.linalg.norm(pursuers - evader, axis=1)[:, None]
    nearest = refined_pp_radius(distance, np.linspace(-np.pi, np.pi, 2001)[None, :], u[:, None], v).min(
        axis=1
    )
    assert active_pursuers(pursuers, evader, u, v, "pp")[np.argmin(nearest)]


@settings(max_examples=40, deadline=None)
@given(SEEDS, st.integers(2, 30), st.sampled_from(["cb", "pp"]))
def test_removing_a_redundant_pursuer_changes_nothing(seed: int, n: int, strategy: str) -> None:
    """A redundant pursuer's region holds the whole boundary: without it, the others keep their status."""
    pursuers, evader, u, v = random_team(seed, n, heterogeneous=True)
    status = active_pursuers(pursuers, evader, u, v, strategy)
    keep = np.flatnonzero(status)
    np.testing.assert_array_equal(
        active_pursuers(pursuers[keep], evader, u[keep], v, strategy), np.ones(len(keep))
    )


@pytest.mark.parametrize("count", [4, 8, 64])
@pytest.mark.parametrize("method", ["fast", "reference"])
def test_pursuers_evenly_around_the_evader_are_all_active(count: int, method: str) -> None:
    """By symmetry every pursuer on a circle centred at the evader contributes an arc (co-circular case)."""
    angles = 2 * np.pi * np.arange(count) / count
    pursuers = 5.0 * np.column_stack([np.cos(angles), np.sin(angles)])
    assert active_pursuers(pursuers, np.zeros(2), 1.0, 0.6, "cb", method=method).all()


@pytest.mark.parametrize("method", ["fast", "reference"])
def test_pursuer_behind_another_is_redundant(method: str) -> None:
    """Collinear pursuers on one side: the far one's disk holds the near one's, so it is redundant."""
    pursuers = np.array([[2.0, 0.0], [4.0, 0.0], [6.0, 0.0], [8.0, 0.0], [10.0, 0.0]])
    status = active_pursuers(pursuers, np.zeros(2), 1.0, 0.6, "cb", method=method)
    np.testing.assert_array_equal(status, [True, False, False, False, False])


@pytest.mark.parametrize(
    ("pursuers", "evader", "u", "v", "needle"),
    [
        ([[1.0, 1.0], [2.0, 0.0]], [1.0, 1.0], 1.0, 0.5, "coincides"),
        ([[1.0, 1.0], [2.0, 0.0]], [0.0, 0.0], [1.0, 0.5], 0.6, "eq. 3.29"),
        ([[1.0, 1.0]], [0.0, 0.0], 1.0, 1.0, "eq. 3.29"),
        (np.zeros((0, 2)), [0.0, 0.0], 1.0, 0.5, "empty"),
        ([1.0, 2.0], [0.0, 0.0], 1.0, 0.5, "(n, 2)"),
    ],
)
def test_bad_input_is_a_spec_error(pursuers, evader, u, v, needle: str) -> None:
    with pytest.raises(SpecError, match=needle.replace("(", r"\(").replace(")", r"\)").replace(".", r"\.")):
        active_pursuers(pursuers, evader, u, v)
