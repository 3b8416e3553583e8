"""Relay pursuit: one active pursuer, one stationary pursuer guarding its Voronoi cell (§2.5).

The stationary pursuer at p_s imposes ‖p_a − p_E‖ ≤ ‖p_s − p_E‖ (eq. 2.28), in reduced form
S = ½(r_a² − r_s²) ≤ 0 (eq. 2.36). Proposition 2 tells where the inactive pursuer matters (the
region of non-degeneracy, vertices A, B, C, arcs of eq. 2.33); the optimal evader path has three
arcs — interior, on the Voronoi boundary, along the active pursuer's line of sight — and leaves the
boundary when the switching condition (eq. 2.41 for R-CB, eq. 2.46 for R-PP) holds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gamespec.pursuit.regions import Frame
from gamespec.pursuit.simulation import Players, Trajectory


def thesis_frame(p_active: np.ndarray, p_stationary: np.ndarray) -> Frame:
    """The frame of §2.5.1: stationary pursuer at the origin, active one at (x_1, 0) with x_1 < 0."""
    diff = np.subtract(p_stationary, p_active)
    return Frame(np.asarray(p_stationary, float), float(np.arctan2(diff[1], diff[0])), float(np.hypot(*diff)))


def voronoi_violation(
    p_active: np.ndarray, p_stationary: np.ndarray, e: np.ndarray, u: float, v: float
) -> np.ndarray:
    """max over [0, t_f] of ‖p_a − p_E‖² − ‖p_s − p_E‖² when E flees along the line of sight (eq. 2.29).

    With p_s at the origin this is a t² + b t + c, a = u² − 2uv, b and c as in Proposition 2, and
    t_f = ‖p_E − p_a‖/(u − v) (eq. 2.2). Positive: the evader would enter the stationary pursuer's
    cell, so the problem is non-degenerate. Vectorized over evader positions ``e`` (..., 2).
    """
    x1 = np.asarray(p_active, float) - p_stationary
    xe = np.asarray(e, float) - p_stationary
    los = xe - x1
    dist = np.linalg.norm(los, axis=-1)
    h = los / dist[..., None]
    a = u**2 - 2 * u * v
    b = 2 * ((u - v) * (h @ x1) - u * np.sum(h * xe, axis=-1))
    c = x1 @ x1 - 2 * (xe @ x1)
    tf = dist / (u - v)
    vertex = np.clip(-b / (2 * a), 0.0, tf) if a != 0 else np.zeros_like(tf)
    return np.max([a * t**2 + b * t + c for t in (np.zeros_like(tf), tf, vertex)], axis=0)


def is_nondegenerate(
    p_active: np.ndarray, p_stationary: np.ndarray, e: np.ndarray, u: float, v: float
) -> np.ndarray:
    """Proposition 2: the evader starts in the active pursuer's Voronoi cell and the quadratic of
    eq. 2.29 has a root in [0, t_f] (vectorized over ``e``)."""
    e = np.asarray(e, float)
    in_cell = np.linalg.norm(e - p_active, axis=-1) <= np.linalg.norm(e - p_stationary, axis=-1)
    return in_cell & (voronoi_violation(p_active, p_stationary, e, u, v) > 0)


def vertices(p_active: np.ndarray, p_stationary: np.ndarray, u: float, v: float) -> dict[str, np.ndarray]:
    """A = (x_1 v/u, 0), B, C = (x_1/2, ±√(v/(2u) − 1/4) |x_1|) in world coordinates (§2.5.1)."""
    frame = thesis_frame(p_active, p_stationary)
    x1 = -frame.d
    height = np.sqrt(max(v / (2 * u) - 0.25, 0.0)) * frame.d
    local = {"A": [x1 * v / u, 0.0], "B": [x1 / 2, height], "C": [x1 / 2, -height]}
    return {k: frame.to_world(np.array(p)) for k, p in local.items()}


def boundary_residual(x1: float, u: float, v: float, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Right-hand side of eq. 2.33 (zero on the arcs AB and AC), in the thesis frame."""
    first = ((v - u) * x1 + u * x) * (x - x1) + u * y**2
    return first**2 - u * (2 * v - u) * x1 * (2 * x - x1) * ((x - x1) ** 2 + y**2)


@dataclass(frozen=True)
class Arcs:
    """The three arcs of an optimal relay path and the switching condition at τ2."""

    tau1: float
    tau2: float
    capture_time: float
    switching_residual: float
    los_heading_error: float

    def as_metrics(self) -> dict[str, float]:
        return {
            "tau1": self.tau1,
            "tau2": self.tau2,
            "interior_duration": self.tau1,
            "boundary_duration": self.tau2 - self.tau1,
            "line_of_sight_duration": self.capture_time - self.tau2,
            "switching_residual": self.switching_residual,
            "line_of_sight_heading_error": self.los_heading_error,
        }


def detect_arcs(
    time: np.ndarray,
    constraint: np.ndarray,
    switching: np.ndarray,
    heading_off_los: np.ndarray,
    tol: float,
) -> Arcs:
    """Split a relay path at τ1 (first touch of S = 0) and τ2 (last time on it).

    ``constraint`` is S(t) (eq. 2.36), ``switching`` the left side of eq. 2.41/2.46 along the path,
    ``heading_off_los`` the evader's heading minus the line of sight of the active pursuer. The
    switching residual is read at τ2; the heading error is the largest |heading_off_los| after τ2.
    """
    on = np.flatnonzero(constraint >= -tol)
    if on.size == 0:
        tc = float(time[-1])
        return Arcs(tc, tc, tc, float("nan"), float("nan"))
    first, last = int(on[0]), int(on[-1])
    after = np.abs(np.angle(np.exp(1j * heading_off_los[last + 1 :])))
    return Arcs(
        tau1=float(time[first]),
        tau2=float(time[last]),
        capture_time=float(time[-1]),
        switching_residual=float(switching[last]),
        los_heading_error=float(after.max()) if after.size else 0.0,
    )


def voronoi_margin(traj: Trajectory, players: Players) -> np.ndarray:
    """S(t) = ½(r_a² − r_s²) (eq. 2.36) for each stationary pursuer s, shape (k, n_stationary)."""
    dist = traj.distances()
    active = players.active
    return 0.5 * (dist[:, active][:, :1] ** 2 - dist[:, ~active] ** 2)
