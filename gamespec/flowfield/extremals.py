"""Forward reachability by extremal shooting: the second, grid-free method for ``T̂`` and ``x_f``.

For ``H(x, λ) = v̂ |λ| + λ · f(x)`` (eq. 5.22) the reachability front at time ``t`` is the end of the
extremals ``ẋ = f(x) + v̂ λ/|λ|``, ``λ̇ = −(∂f/∂x)ᵀ λ`` from ``x(0) = x₀`` and every initial
direction ``λ(0) = (cos θ, sin θ)`` (Pontryagin's principle; the characteristics of eq. 5.22). All
directions of both agents are integrated together by classical RK4 with a fixed step. Capture is the
first time the evader's front lies inside the pursuer's closed front, found from the signed distance
of the evader's front points to the pursuer's front polygon (the margin of
:mod:`~gamespec.flowfield.capture`, here positive outside). Assumes the fronts do not fold
(extremals do not cross), as holds for the smooth, mildly sheared flows of chapter 5.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from matplotlib.path import Path

from gamespec.flowfield.budget import UNLIMITED, Budget
from gamespec.flowfield.capture import first_zero, refined_peak
from gamespec.flowfield.field import FlowField


def _rate(field: FlowField, speeds: np.ndarray, state: np.ndarray) -> np.ndarray:
    """Right-hand side for ``state`` (agents, M, 4) = (x, λ)."""
    x, lam = state[..., :2], state[..., 2:]
    direction = lam / np.linalg.norm(lam, axis=-1, keepdims=True)
    jac = field.jacobian(x)
    dx = field.drift(x) + speeds[:, None, None] * direction
    dlam = -np.einsum("...ji,...j->...i", jac, lam)
    return np.concatenate([dx, dlam], axis=-1)


class ExtremalMarch:
    """The extremals of several agents from ``directions`` equally spaced initial angles (or the
    given ``theta``), advanced by RK4."""

    def __init__(
        self,
        field: FlowField,
        origins: np.ndarray,
        speeds: np.ndarray,
        directions: int,
        theta: np.ndarray | None = None,
    ) -> None:
        if theta is None:
            theta = np.linspace(0.0, 2 * np.pi, directions, endpoint=False)
        lam0 = np.stack([np.cos(theta), np.sin(theta)], axis=-1)
        origins = np.asarray(origins, dtype=float)
        shape = (len(origins), directions, 2)
        self.field = field
        self.speeds = np.asarray(speeds, dtype=float)
        self.state = np.concatenate(
            [np.broadcast_to(origins[:, None, :], shape), np.broadcast_to(lam0, shape)], axis=-1
        )

    @property
    def front(self) -> np.ndarray:
        """The current front points (agents, M, 2)."""
        return self.state[..., :2].copy()

    def step(self, h: float) -> None:
        s = self.state
        k1 = _rate(self.field, self.speeds, s)
        k2 = _rate(self.field, self.speeds, s + h / 2 * k1)
        k3 = _rate(self.field, self.speeds, s + h / 2 * k2)
        k4 = _rate(self.field, self.speeds, s + h * k3)
        self.state = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


def signed_distance(points: np.ndarray, polygon: np.ndarray) -> np.ndarray:
    """Distance of ``points`` (P, 2) to the closed ``polygon`` (M, 2), negative inside."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    ab = b - a
    rel = points[:, None, :] - a[None]
    w = np.clip(np.einsum("pmi,mi->pm", rel, ab) / np.einsum("mi,mi->m", ab, ab), 0.0, 1.0)
    distance = np.linalg.norm(rel - w[..., None] * ab[None], axis=-1).min(axis=1)
    inside = Path(polygon).contains_points(points)
    return np.where(inside, -distance, distance)


def front_margin(pursuer: np.ndarray, evader: np.ndarray) -> tuple[float, np.ndarray]:
    """Largest signed distance of the evader's (closed) front outside the pursuer's front, and where
    (refined by a parabola through the three samples about the largest)."""
    d = signed_distance(evader, pursuer)
    shift = 1 - int(np.argmax(d))
    value, point = refined_peak(np.roll(d, shift)[:3], np.roll(evader, shift, axis=0)[:3], 1)
    return value, point


@dataclass(frozen=True)
class ExtremalReach:
    """Capture time and point by extremal shooting (None when no capture before ``t_max``, or
    ``timed_out``: the budget's time limit stopped the march) and the fronts (S, 2, M, 2) at
    ``times``."""

    times: np.ndarray
    fronts: np.ndarray
    capture_time: float | None
    capture_point: np.ndarray | None
    timed_out: bool = False


def capture_by_extremals(
    field: FlowField,
    origins: np.ndarray,
    speeds: np.ndarray,
    t_max: float,
    *,
    directions: int = 720,
    dt: float = 2e-3,
    check_every: int = 10,
    budget: Budget = UNLIMITED,
) -> ExtremalReach:
    """March until every evader front point is inside the pursuer's front (checked every
    ``check_every`` steps), then find the zero of the signed margin step by step in that bracket;
    ``budget``: the time limit and the progress line, every ``check_every`` steps."""
    march = ExtremalMarch(field, origins, speeds, directions)
    fronts = [march.front]
    count = int(np.ceil(t_max / dt))
    h = t_max / count
    for k in range(1, count + 1):
        march.step(h)
        fronts.append(march.front)
        if k % check_every and k != count:
            continue
        budget.advance(f"extremals, t = {k * h:.3g} of at most {t_max:g}")
        if budget.expired():
            return ExtremalReach(h * np.arange(len(fronts)), np.stack(fronts), None, None, timed_out=True)
        if Path(fronts[-1][0]).contains_points(fronts[-1][1]).all():
            break
    times = h * np.arange(len(fronts))
    stacked = np.stack(fronts)
    fine = np.arange(max(0, len(fronts) - 1 - check_every), len(fronts))
    found = [front_margin(stacked[k, 0], stacked[k, 1]) for k in fine]
    zero = first_zero(times[fine], np.array([m for m, _ in found]))
    if zero is None:
        return ExtremalReach(times, stacked, None, None)
    k, capture_time = zero
    w = (capture_time - times[fine[k]]) / h
    before, after = found[k][1], found[k + 1][1]
    return ExtremalReach(times, stacked, capture_time, (1 - w) * before + w * after)
