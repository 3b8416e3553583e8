"""True dynamics of the engagement in the inertial frame (eqs. 2.1, 3.1), integrated to capture.

Pure-pursuit pursuers head along their line of sight, constant-bearing ones solve eq. 3.3 for the
root that closes the distance, stationary ones stay put. The evader follows a heading law
``theta_E(t, pursuers, evader)`` (a constant heading is the simplest). Integration stops at capture:
the first time an active pursuer is within the capture radius (Definition 1).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from gamespec.pursuit.bearing import constant_bearing_headings, line_of_sight_angles
from gamespec.specs.engagement import EngagementSpec

HeadingLaw = Callable[[float, np.ndarray, np.ndarray], float]
"""``theta_E(t, P, E)``: the evader's heading from time, pursuer positions (n, 2) and its position."""


@dataclass(frozen=True)
class Players:
    """An engagement as arrays: what the geometry and the simulator work on."""

    names: tuple[str, ...]
    positions: np.ndarray
    speeds: np.ndarray
    strategies: tuple[str, ...]
    evader: np.ndarray
    v: float
    eps: float

    @classmethod
    def from_spec(cls, spec: EngagementSpec) -> Players:
        """The arrays of an engagement spec (a stationary pursuer gets speed 0)."""
        return cls(
            names=tuple(p.name for p in spec.pursuers),
            positions=np.array([p.position for p in spec.pursuers], dtype=float),
            speeds=np.array([0.0 if p.strategy == "stationary" else p.speed for p in spec.pursuers]),
            strategies=tuple(p.strategy for p in spec.pursuers),
            evader=np.array(spec.evader.position, dtype=float),
            v=spec.evader.speed,
            eps=spec.capture_radius,
        )

    @property
    def active(self) -> np.ndarray:
        """Boolean mask of the pursuers that move."""
        return np.array([s != "stationary" for s in self.strategies])

    def distances(self) -> np.ndarray:
        """Initial distances r_i(0) (eq. 3.4)."""
        return np.hypot(*(self.evader - self.positions).T)

    def los_angles(self) -> np.ndarray:
        """Initial line-of-sight angles φ_i(0) = atan2(y_E − y_i, x_E − x_i) (eq. 3.17)."""
        return line_of_sight_angles(self.positions, self.evader)

    def subset(self, indices: list[int]) -> Players:
        """The same engagement with only the pursuers at ``indices``."""
        idx = list(indices)
        return Players(
            names=tuple(self.names[i] for i in idx),
            positions=self.positions[idx],
            speeds=self.speeds[idx],
            strategies=tuple(self.strategies[i] for i in idx),
            evader=self.evader,
            v=self.v,
            eps=self.eps,
        )


def pursuer_velocities(players: Players, P: np.ndarray, E: np.ndarray, theta_E: float) -> np.ndarray:
    """Velocities (n, 2) of the pursuers at positions ``P`` against an evader at ``E`` heading ``theta_E``.

    PP: θ_i = φ_i. CB: u_i sin(θ_i − φ_i) = v sin(θ_E − φ_i) with cos(θ_i − φ_i) > 0, so that the
    distance decreases (eq. 3.3). Stationary: at rest.
    """
    sight = E - P
    distance = np.hypot(sight[:, 0], sight[:, 1])
    along = sight / np.where(distance > 0, distance, 1.0)[:, None]
    if "cb" in players.strategies:
        cb = np.array([s == "cb" for s in players.strategies])
        phi = np.arctan2(sight[:, 1], sight[:, 0])
        heading = constant_bearing_headings(phi, players.speeds, players.v, theta_E)
        along = np.where(cb[:, None], np.column_stack([np.cos(heading), np.sin(heading)]), along)
    return players.speeds[:, None] * along


@dataclass(frozen=True)
class Trajectory:
    """A simulated engagement: positions on a time grid and how it ended."""

    time: np.ndarray
    pursuers: np.ndarray
    evader: np.ndarray
    heading: np.ndarray
    captured: bool

    @property
    def capture_time(self) -> float:
        """The time the simulation stopped (the capture time when ``captured``)."""
        return float(self.time[-1])

    def distances(self) -> np.ndarray:
        """Distances r_i(t), shape (k, n)."""
        return np.linalg.norm(self.evader[:, None, :] - self.pursuers, axis=2)


def simulate(
    players: Players,
    heading: HeadingLaw | float,
    t_max: float,
    *,
    samples: int = 400,
    rtol: float = 1e-10,
    method: str = "RK45",
) -> Trajectory:
    """Integrate eq. 2.1/3.1 from the initial positions until capture or ``t_max`` (``method``: a
    :func:`scipy.integrate.solve_ivp` integrator)."""
    law: HeadingLaw = (lambda t, P, E: heading) if isinstance(heading, int | float) else heading
    n = len(players.names)
    active = players.active

    def unpack(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return z[: 2 * n].reshape(n, 2), z[2 * n :]

    def rhs(t: float, z: np.ndarray) -> np.ndarray:
        P, E = unpack(z)
        theta_E = law(t, P, E)
        rate = np.empty_like(z)
        rate[: 2 * n] = pursuer_velocities(players, P, E, theta_E).ravel()
        rate[2 * n :] = players.v * math.cos(theta_E), players.v * math.sin(theta_E)
        return rate

    def capture(t: float, z: np.ndarray) -> float:
        P, E = unpack(z)
        return float(np.min(np.hypot(*(E - P[active]).T)) - players.eps)

    capture.terminal = True
    capture.direction = -1
    z0 = np.concatenate([players.positions.ravel(), players.evader])
    sol = solve_ivp(
        rhs, (0.0, t_max), z0, method=method, rtol=rtol, atol=rtol * 1e-2, dense_output=True, events=capture
    )
    t_end = float(sol.t[-1])
    time = np.linspace(0.0, t_end, samples)
    z = sol.sol(time).T
    pursuers = z[:, : 2 * n].reshape(-1, n, 2)
    evader = z[:, 2 * n :]
    theta = np.array([law(t, P, E) for t, P, E in zip(time, pursuers, evader, strict=True)])
    return Trajectory(time, pursuers, evader, theta, captured=bool(sol.t_events[0].size))


def capture_bound(players: Players) -> float:
    """A time by which capture is certain whatever the evader does: ṙ_i ≤ v − u_i for a PP or CB
    pursuer (eqs. 2.8, 3.2), so max_i (r_i(0) − ε)/(u_i − v) over the active pursuers bounds it."""
    active = players.active
    return float(np.max((players.distances()[active] - players.eps) / (players.speeds[active] - players.v)))


def simulate_to_capture(
    players: Players, heading: HeadingLaw | float, *, rtol: float = 1e-10, method: str = "RK45"
) -> Trajectory:
    """The true dynamics (eq. 2.1) under an evader heading (constant or a law), until capture: the
    one simulator behind guesses, closed forms and the re-simulation check of every solution."""
    return simulate(players, heading, 1.01 * capture_bound(players), rtol=rtol, method=method)
