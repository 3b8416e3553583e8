"""Allocation of pursuers to evaders: AVAA (thesis §3.4) and A2 (§3.5).

Both run the same iteration and differ only in how a pursuer active against several evaders is
tied: AVAA takes the nearest evader, ``argmin_j |p_i - e_j|``; A2 the one it can capture soonest,
``argmin_j |p_i - e_j| / (u_i + v_j)``, which is AVAA's rule for homogeneous teams.

Steps (§3.4): (a) the initial allocation ``I(j)`` is the set of pursuers active against evader
``j`` (:func:`~gamespec_geometric.active.active_set`); if no pursuer is active against two evaders,
``F = I``. Otherwise ``G(j)`` keeps the pursuers of ``I(j)`` that pick ``j`` by the tie-break. (b)
With ``P_u`` the pursuers active against no evader, ``I'(j)`` is the active set of ``G(j) ∪ P_u``.
(c) Repeat with ``I'`` until no pursuer is shared. The thesis does not bound the number of rounds;
after ``max_rounds`` (default ``n + 1``) the last ``G``, which shares no pursuer, is returned. Either
way the pair realizing the current shortest time stays assigned (Lemmas 5 and 7).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from gamespec_geometric.active import Method, TeamStrategy, active_in, capture_regions

Algorithm = Literal["avaa", "a2"]
UNASSIGNED = -1


@dataclass(frozen=True)
class Allocation:
    """The final allocation ``F``: ``assignment[i]`` is pursuer ``i``'s evader, or -1 (redundant)."""

    assignment: np.ndarray
    rounds: int


def tie_break_cost(
    pursuers: np.ndarray,
    evaders: np.ndarray,
    pursuer_speeds: np.ndarray,
    evader_speeds: np.ndarray,
    algorithm: Algorithm,
) -> np.ndarray:
    """``(n, m)`` cost that a shared pursuer minimizes: distance (AVAA) or time to capture (A2)."""
    distance = np.linalg.norm(pursuers[:, None, :] - evaders[None, :, :], axis=2)
    if algorithm == "avaa":
        return distance
    return distance / (pursuer_speeds[:, None] + evader_speeds[None, :])


def allocate(
    pursuers: np.ndarray,
    evaders: np.ndarray,
    pursuer_speeds: np.ndarray,
    evader_speeds: np.ndarray,
    *,
    algorithm: Algorithm = "a2",
    strategy: TeamStrategy = "cb",
    method: Method = "fast",
    samples: int = 64,
    max_rounds: int | None = None,
) -> Allocation:
    """Run AVAA or A2 to the final allocation ``F`` (steps (a)–(c) of §3.4)."""
    n, m = len(pursuers), len(evaders)
    cost = tie_break_cost(pursuers, evaders, pursuer_speeds, evader_speeds, algorithm)
    regions = [
        capture_regions(pursuers, evaders[j], pursuer_speeds, evader_speeds[j], strategy, samples)
        for j in range(m)
    ]
    candidates = np.ones((m, n), dtype=bool)
    checked: list[np.ndarray | None] = [None] * m
    initial = np.zeros((m, n), dtype=bool)
    chosen = np.full(n, UNASSIGNED)
    for rounds in range(1, (max_rounds or n + 1) + 1):
        for j in range(m):
            members = np.flatnonzero(candidates[j])
            if len(members) and method == "fast":
                members = members[regions[j].take(members).may_touch()]
            if checked[j] is not None and np.array_equal(members, checked[j]):
                continue
            checked[j] = members
            initial[j] = False
            if len(members):
                initial[j, members] = active_in(regions[j].take(members), method)
        shared = initial.sum(axis=0)
        chosen = np.where(shared > 0, np.argmin(np.where(initial.T, cost, np.inf), axis=1), UNASSIGNED)
        if shared.max(initial=0) <= 1:
            return Allocation(chosen, rounds)
        kept = initial & (chosen[None, :] == np.arange(m)[:, None])
        candidates = kept | (shared == 0)[None, :]
    return Allocation(chosen, rounds)
