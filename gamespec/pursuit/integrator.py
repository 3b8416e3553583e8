"""The true dynamics of an engagement (eqs. 2.1, 3.1, 3.3) integrated to capture by a Numba-compiled
classical RK4, the evader's heading a piecewise polynomial of time (plus the line of sight's angle).

One loop over the steps, every pursuer's velocity in registers: pure pursuit along the line of
sight, constant bearing ``θ_i = φ_i + asin(v sin(θ_E − φ_i) / u_i)`` (eq. 3.3, the ratio clipped to
[−1, 1] as :func:`gamespec.pursuit.bearing.constant_bearing_headings`), stationary at rest. The
heading is ``θ_E = θ(t)`` or, in the line-of-sight frame, ``θ(t) + φ_1`` with ``φ_1`` read from the
stage's positions. Steps shrink with the nearest pursuer's distance r (near capture a line of
sight turns at up to (u + v)/r) and never cross a mesh point of the heading. After each step the
capture function ``g = min_i |E − P_i| − ε`` over the active pursuers is evaluated; the first step
where it falls from positive to ``≤ 0`` holds the capture instant, found by bisection of ``g`` on
the step's cubic Hermite interpolant (the states and rates at both ends: third order, as RK4's
dense output; :func:`hermite`). Compiled on first use and cached on disk (``cache=True``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

PURE_PURSUIT, CONSTANT_BEARING, STATIONARY = 0, 1, 2
"""Strategy codes of the compiled loop."""
SHORTEST = 1e-6
"""No step is shorter than this fraction of the longest (a distance that reaches 0, at ε = 0, would
stop the clock)."""
BISECTIONS = 60
"""Halvings of the capture step's fraction (2^-60 of a step: below rounding)."""


@njit(cache=True, error_model="numpy")
def _rate(
    z: np.ndarray,
    theta: float,
    speeds: np.ndarray,
    strategy: np.ndarray,
    v: float,
    line_of_sight: bool,
    out: np.ndarray,
) -> None:
    n = speeds.size
    ex, ey = z[2 * n], z[2 * n + 1]
    if line_of_sight:
        theta += math.atan2(ey - z[1], ex - z[0])
    for i in range(n):
        dx, dy = ex - z[2 * i], ey - z[2 * i + 1]
        if strategy[i] == CONSTANT_BEARING:
            phi = math.atan2(dy, dx)
            ratio = v * math.sin(theta - phi) / speeds[i] if speeds[i] > 0 else 0.0
            heading = phi + math.asin(min(1.0, max(-1.0, ratio)))
            out[2 * i], out[2 * i + 1] = speeds[i] * math.cos(heading), speeds[i] * math.sin(heading)
        else:
            r = math.hypot(dx, dy)
            scale = speeds[i] / r if r > 0 else speeds[i]
            out[2 * i], out[2 * i + 1] = scale * dx, scale * dy
    out[2 * n], out[2 * n + 1] = v * math.cos(theta), v * math.sin(theta)


@njit(cache=True, error_model="numpy")
def _gap(z: np.ndarray, active: np.ndarray, eps: float) -> float:
    n = active.size
    ex, ey = z[2 * n], z[2 * n + 1]
    out = math.inf
    for i in range(n):
        if active[i]:
            out = min(out, math.hypot(ex - z[2 * i], ey - z[2 * i + 1]))
    return out - eps


@njit(cache=True, error_model="numpy")
def _hermite_at(
    z0: np.ndarray, z1: np.ndarray, f0: np.ndarray, f1: np.ndarray, h: float, s: float, out: np.ndarray
) -> None:
    """``out`` = the cubic Hermite interpolant of a step of length ``h`` at its fraction ``s``."""
    s2, s3 = s * s, s * s * s
    a, b = 2 * s3 - 3 * s2 + 1, s3 - 2 * s2 + s
    c, d = -2 * s3 + 3 * s2, s3 - s2
    for j in range(z0.size):
        out[j] = a * z0[j] + b * h * f0[j] + c * z1[j] + d * h * f1[j]


@njit(cache=True, error_model="numpy")
def _heading(mesh: np.ndarray, coefficients: np.ndarray, k: int, t: float) -> float:
    """Interval ``k``'s polynomial (highest power first, in the local time) at ``t``."""
    s = (t - mesh[k]) / (mesh[k + 1] - mesh[k])
    value = 0.0
    for c in coefficients[k]:
        value = value * s + c
    return value


@njit(cache=True, error_model="numpy")
def _grown(a: np.ndarray) -> np.ndarray:
    out = np.empty((2 * a.shape[0], *a.shape[1:]))
    out[: a.shape[0]] = a
    return out


@njit(cache=True, error_model="numpy")
def integrate(
    z0: np.ndarray,
    t_max: float,
    mesh: np.ndarray,
    coefficients: np.ndarray,
    speeds: np.ndarray,
    strategy: np.ndarray,
    active: np.ndarray,
    v: float,
    eps: float,
    line_of_sight: bool,
    fraction: float,
    longest: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float]:
    """RK4 from ``z0`` (pursuers' x, y interleaved, then the evader's) until capture or ``t_max``,
    the heading's time part the polynomials of ``mesh`` (``coefficients[k]``: interval k's; the last
    one continued past the mesh). A step is at most ``longest`` and at most ``fraction`` of the
    nearest active pursuer's distance (in the line-of-sight frame also the first pursuer's) over
    the fastest closing speed (the rate a line of sight turns at), and ends on the next mesh point
    rather than cross it (its three stages from its own interval). Returns the step edges, the
    states at them, the rates at each step's start and end (each with its own step's heading) and
    the capture time (NaN without capture; in the last step)."""
    d, n, intervals = z0.size, speeds.size, mesh.size - 1
    fastest = v + (np.max(speeds) if n else 0.0)
    rounding = 1e-9 * (mesh[-1] - mesh[0])
    capacity = 1024
    edges, states = np.empty(capacity + 1), np.empty((capacity + 1, d))
    starts, ends = np.empty((capacity, d)), np.empty((capacity, d))
    k1, k2, k3, k4, w = np.empty(d), np.empty(d), np.empty(d), np.empty(d), np.empty(d)
    edges[0], states[0] = 0.0, z0
    before = _gap(z0, active, eps)
    t, k, step, captured_at = 0.0, 0, 0, math.nan
    while t < t_max and math.isnan(captured_at):
        while k < intervals - 1 and mesh[k + 1] <= t + rounding:
            k += 1
        z = states[step]
        nearest = math.inf
        for i in range(n):
            if active[i] or (line_of_sight and i == 0):
                nearest = min(nearest, math.hypot(z[2 * n] - z[2 * i], z[2 * n + 1] - z[2 * i + 1]))
        h = min(longest, max(fraction * nearest / fastest, SHORTEST * longest), t_max - t)
        if k < intervals - 1 and t + h > mesh[k + 1] - rounding:
            h = mesh[k + 1] - t
        if step == capacity:
            edges, states, starts, ends = _grown(edges), _grown(states), _grown(starts), _grown(ends)
            capacity *= 2
        theta0 = _heading(mesh, coefficients, k, t)
        theta1 = _heading(mesh, coefficients, k, t + 0.5 * h)
        theta2 = _heading(mesh, coefficients, k, t + h)
        _rate(z, theta0, speeds, strategy, v, line_of_sight, k1)
        for j in range(d):
            w[j] = z[j] + 0.5 * h * k1[j]
        _rate(w, theta1, speeds, strategy, v, line_of_sight, k2)
        for j in range(d):
            w[j] = z[j] + 0.5 * h * k2[j]
        _rate(w, theta1, speeds, strategy, v, line_of_sight, k3)
        for j in range(d):
            w[j] = z[j] + h * k3[j]
        _rate(w, theta2, speeds, strategy, v, line_of_sight, k4)
        new = states[step + 1]
        for j in range(d):
            new[j] = z[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
        starts[step] = k1
        _rate(new, theta2, speeds, strategy, v, line_of_sight, ends[step])
        after = _gap(new, active, eps)
        if before > 0 and after <= 0:
            low, high = 0.0, 1.0
            for _ in range(BISECTIONS):
                mid = 0.5 * (low + high)
                _hermite_at(z, new, k1, ends[step], h, mid, w)
                if _gap(w, active, eps) > 0:
                    low = mid
                else:
                    high = mid
            captured_at = t + high * h
        before = after
        t = t_max if t_max - (t + h) <= rounding * 1e-3 else t + h
        step += 1
        edges[step] = t
    return edges[: step + 1], states[: step + 1], starts[:step], ends[:step], captured_at


def hermite(
    edges: np.ndarray, states: np.ndarray, starts: np.ndarray, ends: np.ndarray, t: np.ndarray
) -> np.ndarray:
    """The cubic Hermite interpolant (rows at ``t``) of the steps between ``edges`` (as many steps
    as ``starts`` has rows; a time past the last edge continues the last step's cubic)."""
    steps = starts.shape[0]
    k = np.clip(np.searchsorted(edges[: steps + 1], t, side="right") - 1, 0, steps - 1)
    h = (edges[k + 1] - edges[k])[:, None]
    s = (t - edges[k])[:, None] / h
    s2, s3 = s * s, s * s * s
    rows: np.ndarray = (
        (2 * s3 - 3 * s2 + 1) * states[k]
        + (s3 - 2 * s2 + s) * h * starts[k]
        + (-2 * s3 + 3 * s2) * states[k + 1]
        + (s3 - s2) * h * ends[k]
    )
    return rows
