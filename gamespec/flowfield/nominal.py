"""Nominal trajectories and controls of both agents (eqs. 5.23–5.26).

From the level sets: ``dx̂/dt = v̂ ∇φ/|∇φ| + f(x̂)`` integrated *backward* from the capture point
``x_f`` at ``T̂`` to ``t = 0`` (RK4, φ linear in time between snapshots, its gradient by second-order
differences, bilinear in space); the distance of ``x̂(0)`` from the true start is the *closure error*.
From the extremals: the extremal of each agent whose end at ``T̂`` is ``x_f``, found by a
one-dimensional search over the initial direction; its miss distance at ``x_f`` is the closure error.
Either way the result is sampled on ``τ_k = k T̂/N`` with ``û_k = v̂ n(x̂(τ_k), τ_k)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from gamespec.flowfield.extremals import ExtremalMarch
from gamespec.flowfield.field import FlowField
from gamespec.flowfield.levelset import LevelSetReach


@dataclass(frozen=True)
class NominalPaths:
    """Both agents' nominal paths: ``times`` (fine, ascending from 0 to T̂), ``positions`` and unit
    ``directions`` (2, len(times), 2), the speeds v̂ and the closure errors (2,) (None for paths
    read back from a covariance game's spec, which the reachability stage checked)."""

    times: np.ndarray
    positions: np.ndarray
    directions: np.ndarray
    speeds: np.ndarray
    closure_error: np.ndarray | None = None

    @property
    def final_time(self) -> float:
        return float(self.times[-1])

    def position(self, t: np.ndarray) -> np.ndarray:
        """``x̂(t)`` of both agents (2, len(t), 2) by cubic splines in time."""
        return CubicSpline(self.times, self.positions, axis=1)(np.asarray(t, dtype=float))

    def sampled(self, steps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``τ_k`` (N+1,), ``x̂_k`` (2, N+1, 2) and the held nominal controls ``û_k`` (2, N, 2) on
        ``τ_k = k T̂/N``: ``û_k`` is the mean of ``v̂ n(t)`` over ``[τ_k, τ_{k+1}]`` (4-point
        Gauss–Legendre), the zero-order hold of eq. 5.24/5.26 (the value at ``τ_0`` alone would be
        the direction at the cone's apex, where ∇φ is undefined)."""
        tau = np.linspace(0.0, self.final_time, steps + 1)
        nodes, weights = np.polynomial.legendre.leggauss(4)
        h = tau[1] - tau[0]
        inner = tau[:-1, None] + h * (nodes + 1) / 2
        direction = _unit(CubicSpline(self.times, self.directions, axis=1)(inner.ravel()))
        mean = np.einsum("asqi,q->asi", direction.reshape(2, steps, 4, 2), weights / 2)
        return tau, self.position(tau), self.speeds[:, None, None] * mean


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-300)


def from_level_sets(
    reach: LevelSetReach, field: FlowField, speeds: np.ndarray, origins: np.ndarray, substeps: int = 2
) -> NominalPaths:
    """Backward RK4 from ``x_f`` along eq. 5.23/5.25, ``substeps`` steps per snapshot interval."""
    grid, snap_t, snaps = reach.grid, reach.snapshot_times, reach.snapshots
    speeds = np.asarray(speeds, dtype=float)

    def normal(x: np.ndarray, t: float) -> np.ndarray:
        k = int(np.clip(np.searchsorted(snap_t, t) - 1, 0, len(snap_t) - 2))
        w = (t - snap_t[k]) / (snap_t[k + 1] - snap_t[k])
        phi = (1 - w) * snaps[k].astype(float) + w * snaps[k + 1].astype(float)
        return _unit(np.stack([grid.interpolate(grid.gradient(phi[i]), x[i]) for i in range(2)]))

    def rate(x: np.ndarray, t: float) -> np.ndarray:
        return speeds[:, None] * normal(x, t) + field.drift(x)

    fractions = np.arange(substeps) / substeps
    nodes = np.append((snap_t[:-1, None] + np.diff(snap_t)[:, None] * fractions).ravel(), snap_t[-1])
    x = np.tile(np.asarray(reach.capture_point, dtype=float), (2, 1))
    positions = [x]
    for t1, t0 in zip(nodes[::-1][:-1], nodes[::-1][1:], strict=True):
        h = t0 - t1
        k1 = rate(x, t1)
        k2 = rate(x + h / 2 * k1, t1 + h / 2)
        k3 = rate(x + h / 2 * k2, t1 + h / 2)
        k4 = rate(x + h * k3, t0)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        positions.append(x)
    positions = np.stack(positions[::-1], axis=1)
    directions = np.stack([normal(positions[:, j], t) for j, t in enumerate(nodes)], axis=1)
    directions[:, 0] = directions[:, 1]  # ∇φ is undefined at the apex x̂(0) = x₀
    closure = np.linalg.norm(positions[:, 0] - np.asarray(origins), axis=-1)
    return NominalPaths(nodes, positions, directions, speeds, closure)


def from_extremals(
    field: FlowField,
    origins: np.ndarray,
    speeds: np.ndarray,
    capture_time: float,
    capture_point: np.ndarray,
    dt: float = 5e-3,
    fan: int = 65,
    rounds: int = 4,
) -> NominalPaths:
    """The extremal of each agent ending nearest ``x_f`` at ``T̂``: a fan of ``fan`` initial
    directions about the best one so far, narrowed ``fan/2``-fold for ``rounds`` rounds."""
    count = int(np.ceil(capture_time / dt))
    h = capture_time / count
    target = np.asarray(capture_point, dtype=float)
    origins = np.asarray(origins, dtype=float)
    speeds = np.asarray(speeds, dtype=float)

    def shoot(theta: np.ndarray, keep: bool) -> tuple[np.ndarray, list[np.ndarray]]:
        """Both agents' extremals from the angles ``theta`` (2, M): the ends, and the states."""
        march = ExtremalMarch(field, origins, speeds, theta.shape[1], theta)
        states = [march.state.copy()] if keep else []
        for _ in range(count):
            march.step(h)
            if keep:
                states.append(march.state.copy())
        return march.front, states

    theta = np.tile(np.linspace(0.0, 2 * np.pi, fan, endpoint=False), (2, 1))
    width = 2 * np.pi
    for _ in range(rounds):
        ends, _ = shoot(theta, keep=False)
        best = theta[np.arange(2), np.argmin(np.linalg.norm(ends - target, axis=-1), axis=1)]
        width *= 4 / fan
        theta = best[:, None] + np.linspace(-width / 2, width / 2, fan)
    ends, _ = shoot(theta, keep=False)
    best = theta[np.arange(2), np.argmin(np.linalg.norm(ends - target, axis=-1), axis=1)]
    end, states = shoot(best[:, None], keep=True)
    path = np.stack(states, axis=2)[:, 0]  # (2, S, 4)
    closure = np.linalg.norm(end[:, 0] - target, axis=-1)
    times = np.linspace(0.0, capture_time, count + 1)
    return NominalPaths(times, path[..., :2], _unit(path[..., 2:]), speeds, closure)
