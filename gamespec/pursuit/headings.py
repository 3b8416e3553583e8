"""The best constant heading of an evader: max over θ_E of min over pursuers of the capture time.

Against a non-maneuvering evader each pursuer i has a capture time t_i(θ_E) (eq. 2.5 for pure
pursuit, a constant closing speed for constant bearing). The evader's best constant heading
maximizes min_i t_i. That maximum is either the peak of one t_i (pure evasion from pursuer i) or a
heading where two capture times are equal (simultaneous capture: eq. 2.27, or the Apollonius
intersection of §2.4.1), so those candidates are all that need to be compared.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

CaptureTimes = Callable[[np.ndarray], np.ndarray]
"""Headings (k,) → capture times (k, n) of the n pursuers against those constant headings."""


@dataclass(frozen=True)
class HeadingChoice:
    """The chosen constant heading, its capture time, and each pursuer's capture time for it."""

    heading: float
    capture_time: float
    times: np.ndarray

    def capturing(self, rtol: float = 1e-9) -> list[int]:
        """Indices of the pursuers that capture at the capture time (within ``rtol``)."""
        return [int(i) for i in np.flatnonzero(self.times <= self.capture_time * (1 + rtol))]


def equal_time_headings(times: CaptureTimes, i: int, j: int, samples: int = 721) -> list[float]:
    """Headings where pursuers i and j capture at the same time (roots of t_i − t_j on (−π, π])."""
    grid = np.linspace(-np.pi, np.pi, samples)
    gap = np.diff(times(grid)[:, [i, j]], axis=1).ravel()
    roots = []
    for k in np.flatnonzero(np.sign(gap[:-1]) * np.sign(gap[1:]) <= 0):
        a, b = grid[k], grid[k + 1]
        if gap[k] == 0:
            roots.append(float(a))
            continue
        roots.append(brentq(lambda th: float(np.diff(times(np.array([th]))[0, [i, j]])[0]), a, b))
    return roots


def best_constant_heading(times: CaptureTimes, peaks: np.ndarray) -> HeadingChoice:
    """max_θ min_i t_i(θ), comparing each pursuer's peak ``peaks[i]`` with all equal-time headings."""
    n = len(peaks)
    candidates = [float(p) for p in peaks]
    for i in range(n):
        for j in range(i + 1, n):
            candidates += equal_time_headings(times, i, j)
    cand = np.array(candidates)
    all_times = times(cand)
    worst = all_times.min(axis=1)
    best = int(np.argmax(worst))
    heading = float(np.angle(np.exp(1j * cand[best])))
    return HeadingChoice(heading, float(worst[best]), all_times[best])
