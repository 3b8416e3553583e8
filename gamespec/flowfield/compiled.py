"""The WENO5 / local Lax–Friedrichs rate of eq. 5.22 compiled by Numba: one loop over the nodes.

The NumPy operator (:func:`gamespec.flowfield.upwind._weno5` and
:meth:`gamespec.flowfield.hamiltonian.FlowHamiltonian.numerical`) makes some forty passes over
arrays of the window's size per axis; here each node reads its 7-point stencils along both axes
once and computes both one-sided WENO5 derivatives (the same Jiang–Peng form, the same ε rule:
:data:`~gamespec.flowfield.upwind.WENO_EPSILON` times the largest squared difference of the
stencil, scaled like the indicators) and the Hamiltonian
``Ĥ = v̂ |p̄| + Σ_i (f_i p_i⁺ − (f_i⁺ + v̂/2) j_i)`` in registers. Same formulas, so the same values to
rounding (``tests/flowfield/test_compiled.py``). Compiled on first use and cached on disk
(``cache=True``), so a later process loads the machine code (about 0.1 s) instead of compiling it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gamespec.flowfield.upwind import GHOSTS, WENO_EPSILON


@njit(cache=True, inline="always", error_model="numpy")
def _side(is0: float, is1: float, is2: float, eps: float, t0: float, t1: float, scale: float) -> float:
    """``Φ/dx`` of one side: ``12Φ = (4α₀ T₀ + (2α₂ − Σα) T₁) / Σα`` (see ``upwind._weno5``)."""
    a0 = 1.0 / ((is0 + eps) * (is0 + eps))
    a1 = 6.0 / ((is1 + eps) * (is1 + eps))
    a2 = 3.0 / ((is2 + eps) * (is2 + eps))
    total = a0 + a1 + a2
    return ((2.0 * a2 - total) * t1 + 4.0 * a0 * t0) / total * scale


@njit(cache=True, inline="always", error_model="numpy")
def indicators(x: float, y: float) -> tuple[float, float, float]:
    """The three smoothness indicators (divided by 3) of the adjacent second differences ``x, y``:
    ``(x − 3y)²``, ``(x + y)²`` and ``(3x − y)²``, each plus ``13/3 (y − x)²``."""
    jump = y - x
    common = jump * jump * (13.0 / 3.0)
    rising = x - 3.0 * y
    middle = x + y
    falling = 3.0 * x - y
    return rising * rising + common, middle * middle + common, falling * falling + common


@njit(cache=True, inline="always", error_model="numpy")
def _weno5_pair(
    v0: float, v1: float, v2: float, v3: float, v4: float, v5: float, v6: float, scale: float, floor: float
) -> tuple[float, float]:
    """``(D⁻φ, D⁺φ)`` at the middle of seven consecutive node values."""
    d0, d1, d2, d3, d4, d5 = v1 - v0, v2 - v1, v3 - v2, v4 - v3, v5 - v4, v6 - v5
    s0, s1, s2, s3, s4 = d1 - d0, d2 - d1, d3 - d2, d4 - d3, d5 - d4
    q1, q2, q3, q4 = d1 * d1, d2 * d2, d3 * d3, d4 * d4
    inner = max(max(q1, q2), max(q3, q4))
    eps_minus = (max(inner, d0 * d0) * WENO_EPSILON + floor) * 4.0
    eps_plus = (max(inner, d5 * d5) * WENO_EPSILON + floor) * 4.0
    central = (7.0 * (d2 + d3) - d1 - d4) * scale
    rise01, _, _ = indicators(s0, s1)
    rise12, mid12, _ = indicators(s1, s2)
    _, mid23, fall23 = indicators(s2, s3)
    _, _, fall34 = indicators(s3, s4)
    t01 = s0 - 2.0 * s1 + s2
    t12 = s1 - 2.0 * s2 + s3
    t23 = s2 - 2.0 * s3 + s4
    minus = central - _side(rise01, mid12, fall23, eps_minus, t01, t12, scale)
    plus = central + _side(fall34, mid23, rise12, eps_plus, t23, t12, scale)
    return minus, plus


@njit(cache=True, error_model="numpy")
def weno5_rate(
    padded: np.ndarray,
    rows: tuple[int, int],
    cols: tuple[int, int],
    spacing: tuple[float, float],
    speed: float,
    flow: np.ndarray,
    weights: np.ndarray,
    out: np.ndarray,
) -> None:
    """``φ_t = −Ĥ`` on the nodes ``rows × cols`` (half-open, in grid indices) of ``padded`` (the
    grid with :data:`GHOSTS` ghost nodes on each side) into ``out`` (the window's shape); ``flow``
    is ``f`` (2, nx, ny) and ``weights`` ``f⁺ + v̂/2`` (2, nx, ny) of the agent."""
    dx, dy = spacing
    sx, sy = 1.0 / (12.0 * dx), 1.0 / (12.0 * dy)
    floor_x, floor_y = 1e-99 * dx * dx, 1e-99 * dy * dy
    g = GHOSTS
    for i in range(rows[1] - rows[0]):
        gi = rows[0] + i
        p = gi + g
        for j in range(cols[1] - cols[0]):
            gj = cols[0] + j
            q = gj + g
            mx, px = _weno5_pair(
                padded[p - 3, q],
                padded[p - 2, q],
                padded[p - 1, q],
                padded[p, q],
                padded[p + 1, q],
                padded[p + 2, q],
                padded[p + 3, q],
                sx,
                floor_x,
            )
            my, py = _weno5_pair(
                padded[p, q - 3],
                padded[p, q - 2],
                padded[p, q - 1],
                padded[p, q],
                padded[p, q + 1],
                padded[p, q + 2],
                padded[p, q + 3],
                sy,
                floor_y,
            )
            jx, jy = px - mx, py - my
            ax, ay = px - 0.5 * jx, py - 0.5 * jy
            h = speed * math.sqrt(ax * ax + ay * ay)
            h += px * flow[0, gi, gj] - jx * weights[0, gi, gj]
            h += py * flow[1, gi, gj] - jy * weights[1, gi, gj]
            out[i, j] = -h
