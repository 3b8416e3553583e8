"""Simulation of a ``pursuit_scenario`` with re-allocation at every time step (thesis §3.3.2–3.5).

Each step: every free evader picks its heading from its strategy; AVAA or A2
(:func:`~gamespec_geometric.allocation.allocate`) assigns the pursuers; an assigned pursuer steers
at its evader by constant bearing (eq. 3.3, the root with ``dr/dt < 0``) or pure pursuit (its
heading is the line of sight, eq. 3.16), a redundant pursuer stops; all move in a straight line for
``time_step`` (eq. 3.1). Capture (eq. 3.5) is detected on the straight segments, so a pursuer cannot
step over a capture disk, and its time is interpolated within the step; a captured evader stays
where it was caught and leaves the game.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from gamespec.pursuit.bearing import constant_bearing_headings, line_of_sight_angles
from gamespec_geometric.active import Method
from gamespec_geometric.allocation import UNASSIGNED, allocate, tie_break_cost
from gamespec_geometric.spec import BlindEvasion, FixedHeading, PureEvasion, PursuitScenarioSpec

HeadingPolicy = Callable[[float, np.ndarray, np.ndarray], float]
"""``policy(t, evader, pursuers) -> heading`` of one evader."""


@dataclass(frozen=True)
class Trajectories:
    """What a simulation produced: positions on the time grid, the allocation in force during the
    step from each grid time (``-1``: redundant; the last row, after the final time, is all ``-1``),
    capture times and capturers (None if not captured), and the checks of Lemmas 5–8: the largest
    one-step rise of the current shortest time between captures and the number of steps whose
    shortest pair was not allocated."""

    time: np.ndarray
    pursuers: np.ndarray
    evaders: np.ndarray
    allocation: np.ndarray
    rounds: np.ndarray
    capture_times: list[float | None]
    capturers: list[int | None]
    shortest_time_increase: float
    shortest_pair_unassigned: int


def heading_policy(
    strategy: FixedHeading | PureEvasion | BlindEvasion, evader: int, horizon: float
) -> HeadingPolicy:
    """The heading rule of one evader: fixed, blind with switching headings (§3.3.2), or pure evasion."""
    if isinstance(strategy, FixedHeading):
        heading = strategy.heading
        return lambda t, e, p: heading
    if isinstance(strategy, BlindEvasion):
        rng = np.random.default_rng([strategy.seed, evader])
        schedule = rng.choice(strategy.headings, size=int(horizon / strategy.switch_period) + 2)
        period = strategy.switch_period
        return lambda t, e, p: float(schedule[int(t / period)])
    return _away_from_nearest


def _away_from_nearest(t: float, evader: np.ndarray, pursuers: np.ndarray) -> float:
    """Pure evasion: run along the line of sight from the nearest pursuer."""
    away = evader - pursuers[np.argmin(np.linalg.norm(pursuers - evader, axis=1))]
    return math.atan2(away[1], away[0])


def pursuer_headings(
    pursuers: np.ndarray,
    targets: np.ndarray,
    pursuer_speeds: np.ndarray,
    target_speeds: np.ndarray,
    target_headings: np.ndarray,
    strategy: str | np.ndarray,
) -> np.ndarray:
    """Heading of each pursuer at its target: pure pursuit, or constant bearing from eq. 3.3 (one
    strategy for all, or one each)."""
    los = line_of_sight_angles(pursuers, targets)
    pp = np.broadcast_to(np.asarray(strategy) == "pp", los.shape)
    if pp.all():
        return los
    return np.where(pp, los, constant_bearing_headings(los, pursuer_speeds, target_speeds, target_headings))


def first_contact(relative: np.ndarray, motion: np.ndarray, radius: float) -> np.ndarray:
    """Fraction ``s`` in [0, 1] of a step at which ``|relative + s motion|`` first reaches ``radius``.

    ``inf`` where it stays outside; 0 where it starts inside. Arrays ``(..., 2)``.
    """
    a = np.sum(motion**2, axis=-1)
    b = 2 * np.sum(relative * motion, axis=-1)
    c = np.sum(relative**2, axis=-1) - radius**2
    disc = b**2 - 4 * a * c
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (-b - np.sqrt(disc)) / (2 * a)
    hit = (disc >= 0) & (a > 0) & (s >= 0) & (s <= 1)
    return np.where(c <= 0, 0.0, np.where(hit, s, np.inf))


@dataclass(frozen=True)
class StepPlan:
    """Velocities for one step, the allocation behind them (global evader indices, -1: redundant),
    AVAA/A2 rounds, and the current shortest time with whether its pair is allocated (Lemmas 5/7)."""

    pursuer_velocity: np.ndarray
    evader_velocity: np.ndarray
    assignment: np.ndarray
    rounds: int
    shortest_time: float
    shortest_pair_allocated: bool


def plan_step(
    spec: PursuitScenarioSpec,
    t: float,
    pursuers: np.ndarray,
    evaders: np.ndarray,
    free: np.ndarray,
    policies: list[HeadingPolicy],
    *,
    method: Method,
    samples: int,
) -> StepPlan:
    """Evader headings, the allocation, and the pursuers' headings (redundant pursuers stop)."""
    u, v = spec.pursuers.speeds(), spec.evaders.speeds()
    idx = np.flatnonzero(free)
    headings = np.array([policies[j](t, evaders[j], pursuers) for j in idx])
    result = allocate(
        pursuers,
        evaders[idx],
        u,
        v[idx],
        algorithm=spec.algorithm,
        strategy=spec.pursuers.strategies(),
        method=method,
        samples=samples,
    )
    local = result.assignment
    cost = tie_break_cost(pursuers, evaders[idx], u, v[idx], spec.algorithm)
    i_star, j_star = np.unravel_index(np.argmin(cost), cost.shape)

    chasing = np.flatnonzero(local >= 0)
    targets = local[chasing]
    theta = pursuer_headings(
        pursuers[chasing],
        evaders[idx][targets],
        u[chasing],
        v[idx][targets],
        headings[targets],
        spec.pursuers.strategies()[chasing],
    )
    pursuer_velocity = np.zeros_like(pursuers)
    pursuer_velocity[chasing] = u[chasing, None] * np.column_stack([np.cos(theta), np.sin(theta)])
    evader_velocity = np.zeros_like(evaders)
    evader_velocity[idx] = v[idx, None] * np.column_stack([np.cos(headings), np.sin(headings)])
    return StepPlan(
        pursuer_velocity,
        evader_velocity,
        np.where(local >= 0, idx[np.maximum(local, 0)], UNASSIGNED),
        result.rounds,
        float(cost.min()),
        bool(local[i_star] == j_star),
    )


def simulate(spec: PursuitScenarioSpec, *, method: Method = "fast", samples: int = 64) -> Trajectories:
    """Run the scenario until every evader is caught or the horizon is reached."""
    pursuers = np.array(spec.pursuers.positions, dtype=float)
    evaders = np.array(spec.evaders.positions, dtype=float)
    n, m = len(pursuers), len(evaders)
    dt, radius = spec.time_step, spec.capture_radius
    policies = [heading_policy(s, j, spec.horizon) for j, s in enumerate(spec.evaders.strategies())]

    capture_times: list[float | None] = [None] * m
    capturers: list[int | None] = [None] * m
    times, p_track, e_track, allocations, rounds = [0.0], [pursuers], [evaders], [], []
    shortest_increase, pair_unassigned = -math.inf, 0
    no_motion = np.zeros((n, m, 2))
    _capture(no_motion, pursuers, evaders, np.ones(m, bool), 0.0, 0.0, radius, capture_times, capturers)

    for k in range(math.ceil(spec.horizon / dt - 1e-9)):
        free = np.array([c is None for c in capture_times])
        if not free.any():
            break
        t = k * dt
        plan = plan_step(spec, t, pursuers, evaders, free, policies, method=method, samples=samples)
        motion = dt * (plan.evader_velocity[None, :, :] - plan.pursuer_velocity[:, None, :])
        caught = _capture(motion, pursuers, evaders, free, t, dt, radius, capture_times, capturers)
        stop = np.ones(m)
        stop[list(caught)] = list(caught.values())
        pursuers = pursuers + dt * plan.pursuer_velocity
        evaders = evaders + dt * stop[:, None] * plan.evader_velocity
        if not caught:
            after = tie_break_cost(
                pursuers, evaders[free], spec.pursuers.speeds(), spec.evaders.speeds()[free], spec.algorithm
            ).min()
            shortest_increase = max(shortest_increase, after - plan.shortest_time)
        pair_unassigned += not plan.shortest_pair_allocated
        times.append((k + 1) * dt)
        p_track.append(pursuers)
        e_track.append(evaders)
        allocations.append(plan.assignment)
        rounds.append(plan.rounds)

    allocations.append(np.full(n, UNASSIGNED))
    return Trajectories(
        time=np.array(times),
        pursuers=np.array(p_track),
        evaders=np.array(e_track),
        allocation=np.array(allocations),
        rounds=np.array(rounds, dtype=int),
        capture_times=capture_times,
        capturers=capturers,
        shortest_time_increase=shortest_increase,
        shortest_pair_unassigned=pair_unassigned,
    )


def _capture(
    motion: np.ndarray,
    pursuers: np.ndarray,
    evaders: np.ndarray,
    free: np.ndarray,
    t: float,
    dt: float,
    radius: float,
    capture_times: list[float | None],
    capturers: list[int | None],
) -> dict[int, float]:
    """Record the free evaders caught during this step; returns evader → fraction of the step."""
    contact = first_contact(evaders[None, :, :] - pursuers[:, None, :], motion, radius)
    caught = {}
    for j in np.flatnonzero(free & np.isfinite(contact).any(axis=0)):
        i = int(np.argmin(contact[:, j]))
        caught[int(j)] = float(contact[i, j])
        capture_times[j] = t + caught[int(j)] * dt
        capturers[j] = i
    return caught
