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
ACCEPTED = 1e-5
"""The best Newton iterate is kept when its characteristic ends within this of the node (relative
to the spacing). Newton can stall above ``NEWTON_TOLERANCE``: the cubic interpolant of the drift
is continuous but its derivatives jump between cells, and a characteristic along a grid line
crosses that seam (measured: misses of 1e-8 to 1.2e-7 at 51² in a jet whose drift is 1e-9 there)."""


@njit(cache=True, error_model="numpy")
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
    fx = fy = fxx = fxy = fyx = fyy = 0.0
    for a in range(4):
        for b in range(4):
            w, wdx, wdy = wx[a] * wy[b], wx[a + 4] * wy[b] / spacing[0], wx[a] * wy[b + 4] / spacing[1]
            gx, gy = flow[0, i0 + a, j0 + b], flow[1, i0 + a, j0 + b]
            fx += w * gx
            fy += w * gy
            fxx += wdx * gx
            fxy += wdy * gx
            fyx += wdx * gy
            fyy += wdy * gy
    return fx, fy, fxx, fxy, fyx, fyy


@njit(cache=True, error_model="numpy")
def _rate(
    flow: np.ndarray,
    lower: tuple[float, float],
    spacing: tuple[float, float],
    speed: float,
    x: float,
    y: float,
    px: float,
    py: float,
) -> tuple[float, float, float, float]:
    """``(ẋ, ẏ, ṗ_x, ṗ_y)`` of the characteristic at ``(x, y, p_x, p_y)``."""
    fx, fy, fxx, fxy, fyx, fyy = _drift(flow, lower, spacing, x, y)
    norm = math.sqrt(px * px + py * py)
    return speed * px / norm + fx, speed * py / norm + fy, -(fxx * px + fyx * py), -(fxy * px + fyy * py)


@njit(cache=True, error_model="numpy")
def _ahead(
    x: float, y: float, px: float, py: float, rate: tuple[float, float, float, float], h: float
) -> tuple[float, float, float, float]:
    """The state ``h`` along ``rate`` (an RK4 stage's point)."""
    return x + h * rate[0], y + h * rate[1], px + h * rate[2], py + h * rate[3]


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
    x, y = origin[0] + radius * nx_, origin[1] + radius * ny_
    fx, fy, _, _, _, _ = _drift(flow, lower, spacing, x, y)
    scale = speed + fx * nx_ + fy * ny_
    px, py = nx_ / scale, ny_ / scale
    h = time / RK4_STEPS
    for _ in range(RK4_STEPS):
        a = _rate(flow, lower, spacing, speed, x, y, px, py)
        b = _rate(
            flow,
            lower,
            spacing,
            speed,
            x + h / 2 * a[0],
            y + h / 2 * a[1],
            px + h / 2 * a[2],
            py + h / 2 * a[3],
        )
        c = _rate(
            flow,
            lower,
            spacing,
            speed,
            x + h / 2 * b[0],
            y + h / 2 * b[1],
            px + h / 2 * b[2],
            py + h / 2 * b[3],
        )
        d = _rate(flow, lower, spacing, speed, x + h * c[0], y + h * c[1], px + h * c[2], py + h * c[3])
        x += h / 6 * (a[0] + 2 * b[0] + 2 * c[0] + d[0])
        y += h / 6 * (a[1] + 2 * b[1] + 2 * c[1] + d[1])
        px += h / 6 * (a[2] + 2 * b[2] + 2 * c[2] + d[2])
        py += h / 6 * (a[3] + 2 * b[3] + 2 * c[3] + d[3])
    return x, y


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
    keep it because no iterate ended within ``ACCEPTED`` of them."""
    nx, ny = values.shape
    tolerance = NEWTON_TOLERANCE * max(spacing[0], spacing[1])
    accepted = ACCEPTED * max(spacing[0], spacing[1])
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
            best, best_time = np.inf, time
            for _ in range(NEWTON_STEPS):
                ex, ey = _end(flow, lower, spacing, speed, origin, radius, angle, time)
                ex, ey = ex - x, ey - y
                miss = math.sqrt(ex * ex + ey * ey)
                if miss < best and math.isfinite(time):
                    best, best_time = miss, time
                if miss <= tolerance:
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
            if best <= accepted:
                values[i, j] = best_time
            else:
                failed += 1
    return failed
