"""The anisotropic Godunov update of the static eq. 5.22, ``v̂ |∇T| + f(x)·∇T = 1``, at one node.

Shared by the fast march (:mod:`gamespec.flowfield.marching`) and the WENO5 defect correction
(:mod:`gamespec.flowfield.defect_correction`). After Sethian & Vladimirsky (2003), on the
four-neighbour stencil:

- each side's one-sided difference is ``p = s (αT − β)/h`` (``s = +1`` from the neighbour below
  the node along the axis, ``−1`` from the one above): ``(1, T₁)`` at first order,
  ``(3/2, 2T₁ − T₂/2)`` at second order where the node beyond has a value, less the side's
  ``shift`` (the defect correction's high-order part, zero in a plain march);
- in each quadrant the two sides make eq. 5.22 a quadratic in ``T``; a root counts only when the
  group velocity ``∂H/∂p = v̂ p/|p| + f`` (eq. 5.23) points from both neighbours into the node;
- along one axis the characteristic runs along that axis at the speed ``f·e + √(v̂² − (f·e⊥)²)``;
- ``T`` is the least admissible candidate (the viscosity solution of a convex ``H``).

Sides are numbered 0: the neighbour at ``i − 1``, 1: ``i + 1``, 2: ``j − 1``, 3: ``j + 1``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

FAR, VALUED, START = 0, 1, 2
"""A node without a value yet, with one, and a start node (fixed)."""
SIDE_STEPS = ((1, 0), (-1, 0), (0, 1), (0, -1))
"""For each side, the step from its neighbour to the node."""


@njit(cache=True, error_model="numpy")
def axis_speed(along: float, across: float, speed: float) -> float:
    """The speed along an axis direction e of an agent steering against the drift's cross part."""
    return along + math.sqrt(max(speed * speed - across * across, 0.0))


@njit(cache=True, error_model="numpy")
def one_sided(
    values: np.ndarray, state: np.ndarray, shift: np.ndarray, i: int, j: int, side: int, order: int
) -> tuple[float, float, float]:
    """``(α, β, T₁)`` of the upwind difference ``(αT − β)/h`` towards node (i, j) from the
    neighbour on ``side`` of value ``T₁`` (module doc); zeros when the neighbour has none."""
    nx, ny = values.shape
    di, dj = SIDE_STEPS[side]
    i1, j1 = i - di, j - dj
    if i1 < 0 or j1 < 0 or i1 >= nx or j1 >= ny or state[i1, j1] == FAR:
        return 0.0, 0.0, 0.0
    t1 = values[i1, j1]
    i2, j2 = i1 - di, j1 - dj
    if order == 2 and 0 <= i2 < nx and 0 <= j2 < ny and state[i2, j2] != FAR:
        t2 = values[i2, j2]
        if math.isfinite(t2):
            return 1.5, 2.0 * t1 - 0.5 * t2 - shift[side, i, j], t1
    return 1.0, t1, t1


@njit(cache=True, error_model="numpy")
def along(alpha: float, beta: float, neighbour: float, travel: float) -> float:
    """The one-dimensional candidate ``(β + h/s)/α`` along an axis, which the characteristic leaves
    from the neighbour: first order (``T₁ + h/s``) where the second-order one is below ``T₁``."""
    candidate = (beta + travel) / alpha
    return candidate if candidate >= neighbour else neighbour + travel


@njit(cache=True, error_model="numpy")
def update(
    values: np.ndarray,
    state: np.ndarray,
    shift: np.ndarray,
    flow: np.ndarray,
    speed: float,
    spacing: tuple[float, float],
    i: int,
    j: int,
    order: int,
) -> float:
    """The least admissible candidate for ``T`` at node (i, j) from its valued neighbours."""
    dx, dy = spacing
    fx, fy = flow[0, i, j], flow[1, i, j]
    best = np.inf
    lower_y = one_sided(values, state, shift, i, j, 2, order)
    upper_y = one_sided(values, state, shift, i, j, 3, order)
    for sy, (ay, by, ty) in ((-1, upper_y), (1, lower_y)):
        if ay > 0.0:
            best = min(best, along(ay, by, ty, dy / axis_speed(sy * fy, fx, speed)))
    for sx, side in ((-1, 1), (1, 0)):
        ax, bx, tx = one_sided(values, state, shift, i, j, side, order)
        if ax == 0.0:
            continue
        best = min(best, along(ax, bx, tx, dx / axis_speed(sx * fx, fy, speed)))
        for sy, (ay, by, ty) in ((-1, upper_y), (1, lower_y)):
            if ay == 0.0 or min(tx, ty) >= best:  # T grows along the characteristic from both
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
