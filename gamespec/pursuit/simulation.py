"""True dynamics of the engagement in the inertial frame (eqs. 2.1, 3.1), integrated to capture.

Pure-pursuit pursuers head along their line of sight, constant-bearing ones solve eq. 3.3 for the
root that closes the distance, stationary ones stay put. The evader follows a heading law
``theta_E(t, pursuers, evader)`` (a constant heading is the simplest). Integration stops at capture:
the first time an active pursuer is within the capture radius (Definition 1).

A constant heading or a :class:`ScheduledHeading` (a signal of time, in the fixed or the first
pursuer's line-of-sight frame: what a solution's heading is,
:func:`gamespec.pursuit.ocp_report.heading_law`) is integrated by the compiled RK4 of
:mod:`gamespec.pursuit.integrator` where asked for (:func:`compiled_integration`, what a study's
points run in; ``method="compiled"`` for one call), its steps never across a mesh point of the
signal, at most ``STEP_FRACTION`` r / (fastest pursuer's speed + the evader's) for the nearest
pursuer's distance r (a pure-pursuit line of sight turns at a rate up to (u + v)/r) and at most
``t_max / MIN_STEPS``. A named SciPy ``method`` (an independent integration, as the analytic
backend's check), any other law (a Python function of the positions) and every integration outside
:func:`compiled_integration` go through :func:`scipy.integrate.solve_ivp` with its capture event.
A compiled integration takes a few ms where SciPy's takes 25-50 ms, but the first one in a process
costs about 0.4 s CPU (Numba's import and the load of its cached machine code), and the very first
on a machine about 8 s (the compilation, cached on disk): a loop of re-simulations gains, a single
``gamespec solve`` of an engagement would lose, so the loop's owner asks for it. The two routes
agree to 1e-9 of the capture time (``tests/pursuit/test_integrator.py``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from gamespec.ocp.control_signal import TranscribedSignal
from gamespec.pursuit.bearing import constant_bearing_headings, line_of_sight_angles
from gamespec.specs.engagement import EngagementSpec

HeadingLaw = Callable[[float, np.ndarray, np.ndarray], float]
"""``theta_E(t, P, E)``: the evader's heading from time, pursuer positions (n, 2) and its position."""
STEP_FRACTION = 0.01
"""The compiled RK4's longest step, as a fraction of r / (fastest pursuer's speed + the evader's), r
the nearest pursuer's distance."""
MIN_STEPS = 10000
"""The compiled RK4's longest step is ``t_max / MIN_STEPS``."""


@dataclass(frozen=True)
class ScheduledHeading:
    """θ_E(t) = ``signal(t)``, plus the first pursuer's line-of-sight angle φ_1 = atan2(y_E − y_1,
    x_E − x_1) when ``line_of_sight`` (the frame of eq. 2.21); a :data:`HeadingLaw` the compiled
    integrator evaluates at all its stages at once."""

    signal: TranscribedSignal
    line_of_sight: bool = False

    @classmethod
    def constant(cls, heading: float) -> ScheduledHeading:
        """A constant heading in the fixed frame (one interval ending at 0: no mesh point in a run)."""
        return cls(TranscribedSignal(np.array([-1.0, 0.0]), np.array([[[heading]]])))

    def __call__(self, t: float, P: np.ndarray, E: np.ndarray) -> float:
        offset = math.atan2(E[1] - P[0, 1], E[0] - P[0, 0]) if self.line_of_sight else 0.0
        return self.signal.at(t)[0] + offset

    def along(self, t: np.ndarray, P: np.ndarray, E: np.ndarray) -> np.ndarray:
        """The headings at times ``t`` along positions ``P`` (k, n, 2) and ``E`` (k, 2)."""
        offset = np.arctan2(E[:, 1] - P[:, 0, 1], E[:, 0] - P[:, 0, 0]) if self.line_of_sight else 0.0
        headings: np.ndarray = self.signal(t)[0] + offset
        return headings


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


_COMPILED: ContextVar[bool] = ContextVar("compiled_integration", default=False)
"""Whether :func:`simulate` integrates by the compiled RK4 (:func:`compiled_integration`), per
thread (a Dask worker runs several points at once)."""


@contextmanager
def compiled_integration() -> Iterator[None]:
    """Within this block, integrate a constant or :class:`ScheduledHeading` heading by the compiled
    RK4 (the module doc says when that pays: a loop of re-simulations, such as a study's points);
    its machine code is loaded on entry."""
    from gamespec.pursuit import integrator  # noqa: F401 (Numba's import and code load, here)

    token = _COMPILED.set(True)
    try:
        yield
    finally:
        _COMPILED.reset(token)


def simulate(
    players: Players,
    heading: HeadingLaw | float,
    t_max: float,
    *,
    samples: int = 400,
    rtol: float = 1e-10,
    method: str | None = None,
) -> Trajectory:
    """Integrate eq. 2.1/3.1 from the initial positions until capture or ``t_max``: by the compiled
    RK4 for a constant or :class:`ScheduledHeading` heading with ``method="compiled"``, or without a
    ``method`` within :func:`compiled_integration`; else by SciPy's ``method`` (RK45 by default) at ``rtol``
    (module doc)."""
    if isinstance(heading, int | float):
        heading = ScheduledHeading.constant(float(heading))
    compiled = method == "compiled" or (method is None and _COMPILED.get())
    if compiled and isinstance(heading, ScheduledHeading):
        return _compiled(players, heading, t_max, samples)
    if method == "compiled":
        raise ValueError("the compiled integrator takes a constant or scheduled heading only")
    return _solve_ivp(players, heading, t_max, samples, rtol, "RK45" if method is None else method)


def _compiled(players: Players, heading: ScheduledHeading, t_max: float, samples: int) -> Trajectory:
    # Numba is imported on first use: importing the pursuit package (the CLI does) stays cheap
    from gamespec.pursuit.integrator import CONSTANT_BEARING, PURE_PURSUIT, STATIONARY, hermite, integrate

    n = len(players.names)
    codes = {"pp": PURE_PURSUIT, "cb": CONSTANT_BEARING, "stationary": STATIONARY}
    strategy = np.array([codes[s] for s in players.strategies], dtype=np.int64)
    z0 = np.concatenate([players.positions.ravel(), players.evader])
    signal = heading.signal
    kinematics = (players.speeds, strategy, players.active, players.v, players.eps, heading.line_of_sight)
    edges, states, starts, ends, captured_at = integrate(
        z0, t_max, signal.mesh, signal.coefficients[0], *kinematics, STEP_FRACTION, t_max / MIN_STEPS
    )
    captured = not math.isnan(captured_at)
    time = np.linspace(0.0, captured_at if captured else t_max, samples)
    z = hermite(edges, states, starts, ends, time)
    pursuers, evader = z[:, : 2 * n].reshape(-1, n, 2), z[:, 2 * n :]
    return Trajectory(time, pursuers, evader, heading.along(time, pursuers, evader), captured)


def _solve_ivp(
    players: Players, law: HeadingLaw, t_max: float, samples: int, rtol: float, method: str
) -> Trajectory:
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
    players: Players, heading: HeadingLaw | float, *, rtol: float = 1e-10, method: str | None = None
) -> Trajectory:
    """The true dynamics (eq. 2.1) under an evader heading (constant or a law), until capture: the
    one simulator behind guesses, closed forms and the re-simulation check of every solution."""
    return simulate(players, heading, 1.01 * capture_bound(players), rtol=rtol, method=method)
