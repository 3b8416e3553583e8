"""Time-to-reach maps by fast marching: the static form of eq. 5.22, ``v̂ |∇T| + f(x)·∇T = 1``.

``T(x)`` is the first time an agent of nominal speed v̂ in the drift ``f`` reaches ``x`` from the
disk of radius ``c`` about ``x₀`` (``T = 0`` on its edge): the set reached at time t is
``{T ≤ t}``, the zero level of eq. 5.22's φ at t started from ``|x − x₀| − c``. Dijkstra-ordered
marching after Sethian (1996) with the anisotropic Godunov update of Sethian & Vladimirsky (2003)
on the four-neighbour stencil, compiled by Numba:

- in each quadrant the one-sided differences (second order, ``(3T − 4T₁ + T₂)/2h``, where the next
  node has a value, as scikit-fmm's ``order=2``; first order otherwise)
  make eq. 5.22 a quadratic in ``T``; its larger root counts only when the group velocity
  ``∂H/∂p = v̂ p/|p| + f`` points from both neighbours into the node (the update is upwind);
- along one axis the characteristic runs along that axis at the speed ``f·e + √(v̂² − (f·e⊥)²)``;
- ``T`` is the least of the admissible candidates (the viscosity solution of a convex ``H``).

A node is re-opened whenever a neighbour's new value changes its own by more than ``REOPEN`` of
it (a label-correcting march): with a drift the upwind neighbour of the characteristic may carry
the larger value, and the second-order update is not monotone in ``T₂``, so a value set
early is corrected, not frozen. Corrections below ``REOPEN`` (1e-9) are left: re-opening on every
change above 1e-12 took 3.3 heap pops a node at 201² and 401² and 1.4–1.6× the CPU, for the
same maps to 1.3e-7 up to 401² (``order`` 2, marched past the ``T`` compared).

The nodes within 1.5 cells of the disk's edge start from the closed form of a uniform flow with the
node's own drift, ``|x − x₀ − fT| = c + v̂T`` (exact there; second-order accurate in a smooth
flow, the distance to the edge being a cell or two). The drift must stay below v̂ in magnitude
(the agent can move against it); the disk must lie inside the grid. Measured against the exact
disks of a uniform flow with ``|f| = v̂/2`` (``tests/flowfield/test_marching.py``,
``benchmarks/test_bench_reach.py``), the largest error over ``0.05 ≤ T ≤ 1.5`` falls at order
1.7–1.9 per halving of the spacing (51² … 401²); it sits near the diagonals, where the
four-neighbour stencil's two one-sided differences meet. Third-order one-sided differences
(``(11T − 18T₁ + 9T₂ − 2T₃)/6h``) were tried: order 2.4–2.8 from 51² to 401² (8.4e-5 at 201²,
ten times below second order), but at 801² an oblique wave of about six cells grows along the
characteristics from T ≈ 0.6 (2.6e-3 at T = 1.5, two hundred times the 401² error); fourth
order leaves nodes unreached from 201², fifth diverges from 26². Hence second order is the
highest offered.
"""

from __future__ import annotations

import heapq
import math

import numpy as np
from numba import njit

from gamespec.flowfield.grid import Grid

_FAR, _VALUED, _START = 0, 1, 2
"""A node without a value yet, with one, and a start node (fixed)."""
REOPEN = 1e-9
"""The relative change of a node's value that re-opens it (module doc)."""


@njit(cache=True, error_model="numpy")
def _uniform_flow_time(rx: float, ry: float, fx: float, fy: float, speed: float, radius: float) -> float:
    """The root of ``|r − fT| = c + v̂T`` (the edge of the disk after T in a uniform flow)."""
    a = speed * speed - fx * fx - fy * fy
    b = rx * fx + ry * fy + radius * speed
    return (-b + math.sqrt(b * b + a * (rx * rx + ry * ry - radius * radius))) / a


@njit(cache=True, error_model="numpy")
def _axis_speed(along: float, across: float, speed: float) -> float:
    """The speed along an axis direction e of an agent steering against the drift's cross part."""
    return along + math.sqrt(max(speed * speed - across * across, 0.0))


@njit(cache=True, error_model="numpy")
def _one_sided(
    values: np.ndarray, state: np.ndarray, i: int, j: int, di: int, dj: int, order: int
) -> tuple[float, float, float]:
    """``(α, β, T₁)`` of the upwind difference ``(αT − β)/h`` towards node (i, j) from the
    neighbour (i − di, j − dj) of value ``T₁``: ``(1.5, 2T₁ − T₂/2)`` at second order where the
    node beyond has a value ``T₂``, ``(1, T₁)`` otherwise; zeros when the neighbour has none."""
    nx, ny = values.shape
    i1, j1 = i - di, j - dj
    if i1 < 0 or j1 < 0 or i1 >= nx or j1 >= ny or state[i1, j1] == _FAR:
        return 0.0, 0.0, 0.0
    t1 = values[i1, j1]
    i2, j2 = i1 - di, j1 - dj
    if order == 2 and 0 <= i2 < nx and 0 <= j2 < ny and state[i2, j2] != _FAR:
        t2 = values[i2, j2]
        if math.isfinite(t2):
            return 1.5, 2.0 * t1 - 0.5 * t2, t1
    return 1.0, t1, t1


@njit(cache=True, error_model="numpy")
def _along(alpha: float, beta: float, neighbour: float, travel: float) -> float:
    """The one-dimensional candidate ``(β + h/s)/α`` along an axis, which the characteristic leaves
    from the neighbour: first order (``T₁ + h/s``) where the second-order one is below ``T₁``."""
    candidate = (beta + travel) / alpha
    return candidate if candidate >= neighbour else neighbour + travel


@njit(cache=True, error_model="numpy")
def _update(
    values: np.ndarray,
    state: np.ndarray,
    flow: np.ndarray,
    speed: float,
    spacing: tuple[float, float],
    i: int,
    j: int,
    order: int,
) -> float:
    """The least admissible candidate for ``T`` at node (i, j) from its accepted neighbours."""
    dx, dy = spacing
    fx, fy = flow[0, i, j], flow[1, i, j]
    best = np.inf
    below = _one_sided(values, state, i, j, 0, -1, order)
    above = _one_sided(values, state, i, j, 0, 1, order)
    for sy, (ay, by, ty) in ((-1, below), (1, above)):
        if ay > 0.0:
            best = min(best, _along(ay, by, ty, dy / _axis_speed(sy * fy, fx, speed)))
    for sx in (-1, 1):
        ax, bx, tx = _one_sided(values, state, i, j, sx, 0, order)
        if ax == 0.0:
            continue
        best = min(best, _along(ax, bx, tx, dx / _axis_speed(sx * fx, fy, speed)))
        for sy, (ay, by, _) in ((-1, below), (1, above)):
            if ay == 0.0:
                continue
            # p = (kx T − mx, ky T − my): p_x = sx (αx T − βx)/dx, likewise y
            kx, mx = sx * ax / dx, sx * bx / dx
            ky, my = sy * ay / dy, sy * by / dy
            k = fx * kx + fy * ky
            m = 1.0 + fx * mx + fy * my  # 1 − f·p = m − kT
            qa = speed * speed * (kx * kx + ky * ky) - k * k
            qb = -2.0 * speed * speed * (kx * mx + ky * my) + 2.0 * m * k
            qc = speed * speed * (mx * mx + my * my) - m * m
            disc = qb * qb - 4.0 * qa * qc
            if qa <= 0.0 or disc < 0.0:
                continue
            for root in (-1.0, 1.0):  # either root may be the upwind one where p and v part
                t = (-qb + root * math.sqrt(disc)) / (2.0 * qa)
                px, py = kx * t - mx, ky * t - my
                norm = math.sqrt(px * px + py * py)
                if m - k * t < 0.0 or norm == 0.0 or t >= best:
                    continue
                vx, vy = speed * px / norm + fx, speed * py / norm + fy
                if sx * vx >= 0.0 and sy * vy >= 0.0:
                    best = t
    return best


@njit(cache=True, error_model="numpy")
def _march(
    values: np.ndarray,
    state: np.ndarray,
    flow: np.ndarray,
    speed: float,
    spacing: tuple[float, float],
    t_max: float,
    order: int,
    reopen: float,
) -> int:
    """Marching from the start nodes in the order of the values, a node re-opened whenever a
    neighbour's new value changes its own by more than ``reopen`` of it (the second-order update
    is not monotone, and with a drift the upwind neighbour may carry the larger value), until no
    value at or below ``t_max`` changes (at most 50 updates a node); returns the number of nodes
    taken from the heap."""
    nx, ny = values.shape
    heap = [(0.0, 0, 0)]
    heap.pop()
    for i in range(nx):
        for j in range(ny):
            if state[i, j] == _START:
                heap.append((values[i, j], i, j))
    heapq.heapify(heap)
    taken, limit = 0, 50 * nx * ny
    while heap:
        t, i, j = heapq.heappop(heap)
        if t != values[i, j]:
            continue
        if t > t_max:
            break
        taken += 1
        for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
            a, b = i + di, j + dj
            if not (0 <= a < nx and 0 <= b < ny) or state[a, b] == _START:
                continue
            t_new = _update(values, state, flow, speed, spacing, a, b, order)
            if abs(t_new - values[a, b]) > reopen * max(1.0, abs(t_new)) and taken < limit:
                values[a, b] = t_new
                state[a, b] = _VALUED
                heapq.heappush(heap, (t_new, a, b))
    return taken


@njit(cache=True, error_model="numpy")
def _start(
    points: np.ndarray,
    flow: np.ndarray,
    speed: float,
    origin: tuple[float, float],
    radius: float,
    reach: float,
    values: np.ndarray,
    state: np.ndarray,
) -> None:
    """Fix every node within ``reach`` of the disk's edge or inside at the closed form."""
    nx, ny = values.shape
    for i in range(nx):
        for j in range(ny):
            rx, ry = points[i, j, 0] - origin[0], points[i, j, 1] - origin[1]
            if math.sqrt(rx * rx + ry * ry) <= radius + reach:
                values[i, j] = _uniform_flow_time(rx, ry, flow[0, i, j], flow[1, i, j], speed, radius)
                state[i, j] = _START
            else:
                values[i, j] = np.inf
                state[i, j] = _FAR


def time_to_reach(
    grid: Grid,
    drift: np.ndarray,
    speed: float,
    origin: tuple[float, float],
    radius: float,
    *,
    t_max: float = np.inf,
    order: int = 2,
    reopen: float = REOPEN,
) -> np.ndarray:
    """``T`` at the nodes (nx, ny) for an agent of speed ``speed`` starting on the disk of
    ``radius`` about ``origin`` in the drift tabulated on the grid (nx, ny, 2) (NaN inside the
    disk beyond the start band, +inf where ``T > t_max``). ``order``: 1 or 2; ``reopen``: the
    relative change that re-opens a node (module doc)."""
    if order not in (1, 2):
        raise ValueError("order must be 1 or 2")
    flow = np.ascontiguousarray(np.moveaxis(np.asarray(drift, dtype=float), -1, 0))
    if np.hypot(flow[0], flow[1]).max() >= speed:
        raise ValueError("the drift must stay below the agent's speed for a time-to-reach map")
    values = np.empty(grid.shape)
    state = np.empty(grid.shape, dtype=np.int8)
    spacing = (float(grid.spacing[0]), float(grid.spacing[1]))
    reach = 1.5 * max(spacing)
    origin_xy = (float(origin[0]), float(origin[1]))
    _start(grid.points, flow, float(speed), origin_xy, float(radius), reach, values, state)
    _march(values, state, flow, float(speed), spacing, float(t_max), order, float(reopen))
    values[values > t_max] = np.inf
    return values
