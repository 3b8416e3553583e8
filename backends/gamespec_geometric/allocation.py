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

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np

from gamespec_geometric.active import Method, Strategy, active_in, capture_regions
from gamespec_geometric.active_many import active_cb_many

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
    strategy: Strategy = "cb",
    method: Method = "fast",
    samples: int = 64,
    max_rounds: int | None = None,
) -> Allocation:
    """Run AVAA or A2 to the final allocation ``F`` (steps (a)–(c) of §3.4).

    The fast CB check runs on all evaders at once (:func:`~gamespec_geometric.active_many.active_cb_many`);
    PP and the reference check go one evader at a time.
    """
    cost = tie_break_cost(pursuers, evaders, pursuer_speeds, evader_speeds, algorithm)
    if strategy == "cb" and method == "fast":
        check = _all_at_once(pursuers, evaders, pursuer_speeds, evader_speeds)
    else:
        check = _one_by_one(pursuers, evaders, pursuer_speeds, evader_speeds, strategy, method, samples)
    return _iterate(cost, check, max_rounds or len(pursuers) + 1)


def _all_at_once(
    pursuers: np.ndarray, evaders: np.ndarray, pursuer_speeds: np.ndarray, evader_speeds: np.ndarray
) -> Callable[[np.ndarray], np.ndarray]:
    """Active sets ``(m, n)`` among candidates (CB, fast), batched over the evaders whose candidates
    changed since the last round."""
    seen = np.zeros((len(evaders), len(pursuers)), dtype=bool)
    initial = np.zeros_like(seen)
    first = [True]

    def check(candidates: np.ndarray) -> np.ndarray:
        changed = np.flatnonzero(np.any(candidates != seen, axis=1) | first[0])
        first[0] = False
        seen[changed] = candidates[changed]
        initial[changed] = active_cb_many(
            pursuers, evaders[changed], pursuer_speeds, evader_speeds[changed], candidates[changed]
        )
        return initial.copy()

    return check


def _one_by_one(
    pursuers: np.ndarray,
    evaders: np.ndarray,
    pursuer_speeds: np.ndarray,
    evader_speeds: np.ndarray,
    strategy: Strategy,
    method: Method,
    samples: int,
) -> Callable[[np.ndarray], np.ndarray]:
    """Active sets ``(m, n)`` among candidates, one evader at a time, skipping unchanged evaders."""
    m, n = len(evaders), len(pursuers)
    regions = [
        capture_regions(pursuers, evaders[j], pursuer_speeds, evader_speeds[j], strategy, samples)
        for j in range(m)
    ]
    checked: list[np.ndarray | None] = [None] * m
    initial = np.zeros((m, n), dtype=bool)

    def check(candidates: np.ndarray) -> np.ndarray:
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
        return initial.copy()

    return check


def _iterate(cost: np.ndarray, check: Callable[[np.ndarray], np.ndarray], max_rounds: int) -> Allocation:
    """Steps (a)–(c) of §3.4 on the ``(n, m)`` tie-break cost, given the active-set check."""
    n, m = cost.shape
    candidates = np.ones((m, n), dtype=bool)
    chosen = np.full(n, UNASSIGNED)
    for rounds in range(1, max_rounds + 1):
        initial = check(candidates)
        shared = initial.sum(axis=0)
        chosen = np.where(shared > 0, np.argmin(np.where(initial.T, cost, np.inf), axis=1), UNASSIGNED)
        if shared.max(initial=0) <= 1:
            return Allocation(chosen, rounds)
        kept = initial & (chosen[None, :] == np.arange(m)[:, None])
        candidates = kept | (shared == 0)[None, :]
    return Allocation(chosen, rounds)
