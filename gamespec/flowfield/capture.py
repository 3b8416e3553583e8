"""The capture condition of Theorem 6 in its instantaneous form (section 5.2): the evader's reachable
set lies inside the pursuer's, ``ℛᵉ(t) ⊆ ℛᵖ(t)``.

On a grid the condition is measured by the *margin* ``m(t) = max over the evader's front of φᵖ``
(the zero contour of φᵉ, interpolated): positive while part of the evader's set is uncovered, zero
when the last uncovered point — the capture point ``x_f`` — is reached. ``m`` is continuous in ``t``,
so the capture time is its first zero, interpolated between time steps. The margin can be read at a
level ``c > 0`` (the sets reached from the disks of radius ``c`` about the starting points).
"""

from __future__ import annotations

from dataclasses import dataclass

import contourpy
import numpy as np

from gamespec.flowfield.band import band_window
from gamespec.flowfield.grid import Grid

PEAK_CELLS = 4.0
"""Half-width, in cells, of the front's arc over which the capture point is fitted."""


def contours(grid: Grid, phi: np.ndarray, level: float = 0.0) -> list[np.ndarray]:
    """The ``level`` contours of node values ``phi`` (nx, ny), each an array (M, 2) of points, traced
    on the rectangle of cells that holds the nodes below ``level`` (every cell the contour crosses)."""
    window = band_window(phi, level, 1)
    if window is None:
        return []
    x, y = (axis[w] for axis, w in zip(grid.axes, window, strict=True))
    generator = contourpy.contour_generator(x, y, phi[window].T, line_type=contourpy.LineType.Separate)
    return [line for line in generator.lines(level) if len(line) > 1]


def refined_peak(values: np.ndarray, points: np.ndarray, k: int) -> tuple[float, np.ndarray]:
    """The parabola through samples k−1, k, k+1 of a front (by arc length): its peak value and point."""
    if k == 0 or k == len(values) - 1:
        return float(values[k]), points[k]
    h1, h2 = np.linalg.norm(np.diff(points[k - 1 : k + 2], axis=0), axis=1)
    y0, y1, y2 = (float(v) for v in values[k - 1 : k + 2])
    if h1 <= 0 or h2 <= 0:
        return float(values[k]), points[k]
    slope = (y1 - y0) / h1  # Newton's divided differences at s = 0, h1, h1 + h2
    c2 = ((y2 - y1) / h2 - slope) / (h1 + h2)
    if c2 >= 0:
        return float(values[k]), points[k]
    c1 = slope - c2 * h1
    peak = float(np.clip(-c1 / (2 * c2), 0.0, h1 + h2))
    segment, start, length = (0, 0.0, h1) if peak <= h1 else (1, h1, h2)
    w = (peak - start) / length
    point = (1 - w) * points[k - 1 + segment] + w * points[k + segment]
    return y0 + (c1 + c2 * peak) * peak, point


def smoothed_peak_point(values: np.ndarray, points: np.ndarray, k: int, width: float) -> np.ndarray | None:
    """Where the least-squares parabola (by arc length) through the samples within ``width`` of
    sample k peaks; None with fewer than five samples or no peak. A flat maximum locates poorly from
    three samples (the interpolation's scatter along the front moves the peak by about its square
    root); a wider fit averages that scatter out."""
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    near = np.abs(s - s[k]) <= width
    if near.sum() < 5:
        return None
    c2, c1, _ = np.polyfit(s[near] - s[k], values[near], 2)
    if c2 >= 0:
        return None
    peak = float(np.clip(-c1 / (2 * c2), s[near].min() - s[k], s[near].max() - s[k])) + s[k]
    return np.array([np.interp(peak, s, points[:, 0]), np.interp(peak, s, points[:, 1])])


@dataclass(frozen=True)
class Margin:
    """``m(t)``: the largest pursuer level on the evader's front, and where it is."""

    value: float
    point: np.ndarray


def margin(grid: Grid, phi_pursuer: np.ndarray, phi_evader: np.ndarray, level: float = 0.0) -> Margin | None:
    """``max (φᵖ − level)`` over the evader's ``level`` contour (None when it is not on the grid)."""
    best: Margin | None = None
    for line in contours(grid, phi_evader, level):
        values = grid.interpolate(phi_pursuer, line) - level
        k = int(np.argmax(values))
        value, point = refined_peak(values, line, k)
        smoothed = smoothed_peak_point(values, line, k, PEAK_CELLS * float(np.max(grid.spacing)))
        point = point if smoothed is None else smoothed
        if best is None or value > best.value:
            best = Margin(value, point)
    return best


def first_zero(times: np.ndarray, margins: np.ndarray) -> tuple[int, float] | None:
    """The index ``k`` with ``m_k > 0 ≥ m_{k+1}`` first, and the interpolated zero in between."""
    crossed = np.flatnonzero((margins[:-1] > 0) & (margins[1:] <= 0))
    if crossed.size == 0:
        return None
    k = int(crossed[0])
    w = margins[k] / (margins[k] - margins[k + 1])
    return k, float(times[k] + w * (times[k + 1] - times[k]))
