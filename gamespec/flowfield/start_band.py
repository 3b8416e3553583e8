"""Start values of a time-to-reach map near the disk, to high order in a non-uniform drift.

A node a cell or two from the disk's edge is reached (or, inside, was left) after a time of the
order of a cell: its ``T`` is the time the characteristic of eq. 5.22 from the edge takes to it.
The characteristics are eq. 5.23 with the costate of the static Hamiltonian
``H = v̂ |p| + f(x)·p``:

    ẋ = v̂ p/|p| + f(x),    ṗ = −(∂f/∂x)ᵀ p,

from ``x = x₀ + c (cos θ, sin θ)`` with ``p`` along the edge's normal ``n`` scaled to ``H = 1``.
Newton's method on ``(θ, T)`` makes the characteristic end at the node (two RK4 steps, the drift
and its Jacobian from the tabulated drift by tensor-product cubic Lagrange interpolation, so the
start error is of fifth order in the spacing, against second order for the uniform-flow closed
form, which is the first guess and stays where Newton fails). In a uniform drift the
characteristics are straight and the shot equals the closed form to rounding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

NEWTON_STEPS = 8
RK4_STEPS = 2
NEWTON_TOLERANCE = 1e-13
"""Newton stops when the characteristic ends within this of the node (relative to the spacing)."""


@njit(cache=True, inline="always", error_model="numpy")
def _cubic(s: float) -> tuple[float, float, float, float, float, float, float, float]:
    """The cubic Lagrange weights on the nodes 0 … 3 at ``s`` and their derivatives."""
    a, b, c, d = s, s - 1.0, s - 2.0, s - 3.0
    return (
        -b * c * d / 6.0,
        a * c * d / 2.0,
        -a * b * d / 2.0,
        a * b * c / 6.0,
        -(c * d + b * d + b * c) / 6.0,
        (c * d + a * d + a * c) / 2.0,
        -(b * d + a * d + a * b) / 2.0,
        (b * c + a * c + a * b) / 6.0,
    )


@njit(cache=True, error_model="numpy")
def _drift(
    flow: np.ndarray, lower: tuple[float, float], spacing: tuple[float, float], x: float, y: float
) -> tuple[float, float, float, float, float, float]:
    """``(f_x, f_y, ∂f_x/∂x, ∂f_x/∂y, ∂f_y/∂x, ∂f_y/∂y)`` at ``(x, y)`` from the 4 × 4 nodes about it."""
    nx, ny = flow.shape[1], flow.shape[2]
    u, v = (x - lower[0]) / spacing[0], (y - lower[1]) / spacing[1]
    i0 = min(max(math.floor(u) - 1, 0), nx - 4)
    j0 = min(max(math.floor(v) - 1, 0), ny - 4)
    wx = _cubic(u - i0)
    wy = _cubic(v - j0)
    out = np.zeros(6)
    for a in range(4):
        for b in range(4):
            w, wdx, wdy = wx[a] * wy[b], wx[a + 4] * wy[b] / spacing[0], wx[a] * wy[b + 4] / spacing[1]
            for k in range(2):
                value = flow[k, i0 + a, j0 + b]
                out[k] += w * value
                out[2 + 2 * k] += wdx * value
                out[3 + 2 * k] += wdy * value
    return out[0], out[1], out[2], out[3], out[4], out[5]


@njit(cache=True, inline="always", error_model="numpy")
def _rate(
    flow: np.ndarray,
    lower: tuple[float, float],
    spacing: tuple[float, float],
    speed: float,
    state: np.ndarray,
) -> np.ndarray:
    """``(ẋ, ṗ)`` of the characteristic at ``state = (x, y, p_x, p_y)``."""
    fx, fy, fxx, fxy, fyx, fyy = _drift(flow, lower, spacing, state[0], state[1])
    norm = math.sqrt(state[2] * state[2] + state[3] * state[3])
    out = np.empty(4)
    out[0] = speed * state[2] / norm + fx
    out[1] = speed * state[3] / norm + fy
    out[2] = -(fxx * state[2] + fyx * state[3])
    out[3] = -(fxy * state[2] + fyy * state[3])
    return out


@njit(cache=True, error_model="numpy")
def _end(
    flow: np.ndarray,
    lower: tuple[float, float],
    spacing: tuple[float, float],
    speed: float,
    origin: tuple[float, float],
    radius: float,
    angle: float,
    time: float,
) -> tuple[float, float]:
    """Where the characteristic from the edge at ``angle`` is after ``time`` (RK4)."""
    nx_, ny_ = math.cos(angle), math.sin(angle)
    state = np.array([origin[0] + radius * nx_, origin[1] + radius * ny_, nx_, ny_])
    fx, fy, _, _, _, _ = _drift(flow, lower, spacing, state[0], state[1])
    state[2:] /= speed + fx * nx_ + fy * ny_
    h = time / RK4_STEPS
    for _ in range(RK4_STEPS):
        k1 = _rate(flow, lower, spacing, speed, state)
        k2 = _rate(flow, lower, spacing, speed, state + 0.5 * h * k1)
        k3 = _rate(flow, lower, spacing, speed, state + 0.5 * h * k2)
        k4 = _rate(flow, lower, spacing, speed, state + h * k3)
        state = state + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    return state[0], state[1]


@njit(cache=True, error_model="numpy")
def shoot(
    values: np.ndarray,
    points: np.ndarray,
    flow: np.ndarray,
    lower: tuple[float, float],
    spacing: tuple[float, float],
    speed: float,
    origin: tuple[float, float],
    radius: float,
    inner: float,
    outer: float,
) -> int:
    """Replace ``T`` at the nodes from ``inner`` inside the edge to ``outer`` outside by the shot
    characteristic's time (module doc); ``values`` holds the first guess. Returns how many nodes
    Newton left at their first guess."""
    nx, ny = values.shape
    tolerance = NEWTON_TOLERANCE * max(spacing[0], spacing[1])
    step = 1e-7
    failed = 0
    for i in range(nx):
        for j in range(ny):
            x, y = points[i, j, 0], points[i, j, 1]
            rx, ry = x - origin[0], y - origin[1]
            distance = math.sqrt(rx * rx + ry * ry)
            if not (radius - inner < distance <= radius + outer):
                continue
            time = values[i, j]
            fx, fy, _, _, _, _ = _drift(flow, lower, spacing, x, y)
            angle = math.atan2(ry - fy * time, rx - fx * time)
            converged = False
            for _ in range(NEWTON_STEPS):
                ex, ey = _end(flow, lower, spacing, speed, origin, radius, angle, time)
                ex, ey = ex - x, ey - y
                if math.sqrt(ex * ex + ey * ey) <= tolerance:
                    converged = True
                    break
                ax, ay = _end(flow, lower, spacing, speed, origin, radius, angle + step, time)
                tx, ty = _end(flow, lower, spacing, speed, origin, radius, angle, time + step)
                jax, jay = (ax - x - ex) / step, (ay - y - ey) / step
                jtx, jty = (tx - x - ex) / step, (ty - y - ey) / step
                det = jax * jty - jay * jtx
                if det == 0.0 or not math.isfinite(det):
                    break
                angle -= (ex * jty - ey * jtx) / det
                time -= (jax * ey - jay * ex) / det
            if converged and math.isfinite(time):
                values[i, j] = time
            else:
                failed += 1
    return failed
