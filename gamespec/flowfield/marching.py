"""Time-to-reach maps by fast marching: the static form of eq. 5.22, ``v̂ |∇T| + f(x)·∇T = 1``.

``T(x)`` is the first time an agent of nominal speed v̂ in the drift ``f`` reaches ``x`` from the
disk of radius ``c`` about ``x₀`` (``T = 0`` on its edge): the set reached at time t is
``{T ≤ t}``, the zero level of eq. 5.22's φ at t started from ``|x − x₀| − c``. Dijkstra-ordered
marching after Sethian (1996) with the anisotropic Godunov update of Sethian & Vladimirsky (2003)
(:mod:`gamespec.flowfield.godunov`: second-order one-sided differences, as scikit-fmm's
``order=2``, where the next node has a value), compiled by Numba.

A node is re-opened whenever a neighbour's new value changes its own by more than ``REOPEN`` of
it (a label-correcting march): with a drift the upwind neighbour of the characteristic may carry
the larger value, and the second-order update is not monotone in ``T₂``, so a value set
early is corrected, not frozen. Corrections below ``REOPEN`` (1e-9) are left: re-opening on every
change above 1e-12 took 3.3 heap pops a node at 201² and 401² and 1.4–1.6× the CPU, for the
same maps to 1.3e-7 up to 401² (``order`` 2, marched past the ``T`` compared).

The nodes within 1.5 cells of the disk's edge start from the closed form of a uniform flow with the
node's own drift, ``|x − x₀ − fT| = c + v̂T``. It is exact in a uniform flow and second-order
accurate in a smooth one, the distance to the edge being a cell or two. The drift must stay below
v̂ in magnitude (the agent can move against it), and the disk must lie inside the grid.

**Order 2.** Measured against the exact disks of a uniform flow with ``|f| = v̂/2``
(``tests/flowfield/test_marching.py``, ``benchmarks/test_bench_reach.py``), the largest error over
``0.05 ≤ T ≤ 1.5`` falls at order 1.7–1.9 per halving of the spacing (51² … 401²). It sits near
the diagonals, where the four-neighbour stencil's two one-sided differences meet.

**Higher one-sided orders in the march.** Third-order one-sided differences
(``(11T − 18T₁ + 9T₂ − 2T₃)/6h``) were tried. They gave order 2.4–2.8 from 51² to 401² (8.4e-5 at
201²), but at 801² an oblique wave grew along the characteristics. Fourth order leaves nodes
unreached, and fifth diverges.

**Order 5, the default.** The second-order march is corrected by fifth-order differences, pass by
pass, in :mod:`gamespec.flowfield.defect_correction`. The start band is shot along the
characteristics to fifth order (:mod:`gamespec.flowfield.start_band`). The march runs
``MARGIN_CELLS`` beyond ``t_max``, so that the stencils of the returned nodes read corrected
values.

Converged (tolerance 1e-11) on the uniform flow, the error is 9.7e-5, 3.8e-6, 1.6e-7, 5.5e-9 and
2.4e-10 on 51² … 801²: order 4.5–4.8 per halving. At the default tolerance the iteration error is
of the order of the tolerance (5.2e-7 at 201²). In the rotating flow of the tests the order is
about 3 up to the grid's edge (its one-sided stencils), and about 4 inside.
"""

from __future__ import annotations

import heapq
import math
import warnings

import numpy as np
from numba import njit

from gamespec.flowfield.defect_correction import correct
from gamespec.flowfield.godunov import FAR, START, VALUED, update
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.start_band import shoot

REOPEN = 1e-9
"""The relative change of a node's value that re-opens it (module doc)."""
TOLERANCE = 1e-7
"""The fifth-order route stops correcting after a pass that changes no value by more than this
times the largest value returned (at least 1). The iteration error is then a few times that
change (the slow mode halves a pass): on the benchmark's uniform flow it is below the map's own
error up to about 150²; at 201² the map is off by 5.2e-7 at this tolerance, 1.6e-7 converged."""
PASSES = 200
"""The fifth-order route's most defect-correction passes."""
MARGIN_CELLS = 6
"""The fifth-order route marches this many cells (at the slowest pace) beyond ``t_max``, so the
fifth-order stencils of the nodes it returns read corrected values."""


@njit(cache=True, error_model="numpy")
def _uniform_flow_time(rx: float, ry: float, fx: float, fy: float, speed: float, radius: float) -> float:
    """The root of ``|r − fT| = c + v̂T`` (the edge of the disk after T in a uniform flow)."""
    a = speed * speed - fx * fx - fy * fy
    b = rx * fx + ry * fy + radius * speed
    return (-b + math.sqrt(b * b + a * (rx * rx + ry * ry - radius * radius))) / a


@njit(cache=True, error_model="numpy")
def _march(
    values: np.ndarray,
    state: np.ndarray,
    shift: np.ndarray,
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
            if state[i, j] == START:
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
            if not (0 <= a < nx and 0 <= b < ny) or state[a, b] == START:
                continue
            t_new = update(values, state, shift, flow, speed, spacing, a, b, order)
            if abs(t_new - values[a, b]) > reopen * max(1.0, abs(t_new)) and taken < limit:
                values[a, b] = t_new
                state[a, b] = VALUED
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
                state[i, j] = START
            else:
                values[i, j] = np.inf
                state[i, j] = FAR


def time_to_reach(
    grid: Grid,
    drift: np.ndarray,
    speed: float,
    origin: tuple[float, float],
    radius: float,
    *,
    t_max: float = np.inf,
    order: int = 5,
    reopen: float = REOPEN,
    tolerance: float = TOLERANCE,
    passes: int = PASSES,
) -> np.ndarray:
    """``T`` at the nodes (nx, ny) for an agent of speed ``speed`` starting on the disk of
    ``radius`` about ``origin`` in the drift tabulated on the grid (nx, ny, 2) (NaN inside the
    disk beyond the start band, +inf where ``T > t_max``).

    ``order``: 1 or 2, the march alone; 5 (the default), the second-order march from start values
    shot along the characteristics (:mod:`gamespec.flowfield.start_band`), then corrected by
    fifth-order differences (:mod:`gamespec.flowfield.defect_correction`) until no value at or
    below ``t_max`` changes by more than ``tolerance`` times the largest in a pass (a
    ``RuntimeWarning`` when ``passes`` passes run out first). ``reopen``: the relative change that
    re-opens a node in the march (module doc)."""
    if order not in (1, 2, 5):
        raise ValueError("order must be 1, 2 or 5")
    if passes < 1 or not tolerance > 0:
        raise ValueError("the correction needs at least one pass and a positive tolerance")
    flow = np.ascontiguousarray(np.moveaxis(np.asarray(drift, dtype=float), -1, 0))
    fastest = float(np.hypot(flow[0], flow[1]).max())
    if fastest >= speed:
        raise ValueError("the drift must stay below the agent's speed for a time-to-reach map")
    values = np.empty(grid.shape)
    state = np.empty(grid.shape, dtype=np.int8)
    spacing = (float(grid.spacing[0]), float(grid.spacing[1]))
    reach = 1.5 * max(spacing)
    origin_xy = (float(origin[0]), float(origin[1]))
    _start(grid.points, flow, float(speed), origin_xy, float(radius), reach, values, state)
    marched_to = float(t_max)
    if order == 5:
        _shot_start(grid, values, flow, float(speed), origin_xy, float(radius), reach)
        marched_to = float(t_max + MARGIN_CELLS * max(spacing) / (speed - fastest))
    shift = np.zeros((4, *grid.shape))
    _march(values, state, shift, flow, float(speed), spacing, marched_to, min(order, 2), float(reopen))
    if order == 5:
        _corrected(values, state, flow, float(speed), spacing, float(t_max), marched_to, tolerance, passes)
    values[values > t_max] = np.inf
    return values


def _shot_start(
    grid: Grid,
    values: np.ndarray,
    flow: np.ndarray,
    speed: float,
    origin: tuple[float, float],
    radius: float,
    reach: float,
) -> None:
    """The start band's values shot along the characteristics, from two cells inside the edge to
    ``reach`` outside (:mod:`gamespec.flowfield.start_band`); a warning where Newton failed."""
    spacing = (float(grid.spacing[0]), float(grid.spacing[1]))
    lower = (float(grid.lower[0]), float(grid.lower[1]))
    failed = shoot(values, grid.points, flow, lower, spacing, speed, origin, radius, 2 * max(spacing), reach)
    if failed:
        warnings.warn(
            f"{failed} start nodes of the time-to-reach map keep the uniform-flow closed form "
            "(second order): shooting their characteristics did not converge",
            RuntimeWarning,
            stacklevel=3,
        )


def _corrected(
    values: np.ndarray,
    state: np.ndarray,
    flow: np.ndarray,
    speed: float,
    spacing: tuple[float, float],
    t_max: float,
    marched_to: float,
    tolerance: float,
    passes: int,
) -> None:
    """The marched map (to ``marched_to``) corrected in place to fifth order
    (:mod:`gamespec.flowfield.defect_correction`); a warning when the passes run out."""
    values[values > marched_to] = np.inf
    state[~np.isfinite(values)] = FAR
    reached = values[values <= t_max]
    allowed = tolerance * max(float(reached.max()) if reached.size else 0.0, 1.0)
    done, change = correct(values, state, flow, speed, spacing, t_max, allowed, int(passes))
    if change > allowed:
        warnings.warn(
            f"the fifth-order correction of the time-to-reach map changed it by {change:.1e} in its "
            f"last of {done} passes (allowed {allowed:.1e})",
            RuntimeWarning,
            stacklevel=3,
        )
