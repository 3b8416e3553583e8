"""A Result's controls as the transcription holds them, as functions of time.

Direct collocation represents a control on each mesh interval by the polynomial through that
interval's own control points: Radau's ``d`` collocation points in ``(t_k, t_{k+1}]`` (degree
``d - 1``, continued to the interval's start, where Radau has no control point), or the two nodes of
a trapezoidal interval (linear). Between intervals a control may jump. The transcription's
:meth:`~gamespec.ocp.transcription.Transcription.result` saves the mesh as
``arrays["control_mesh"]`` (the interval boundaries in time); a scheme is told apart by its data:
trapezoidal control points include the mesh's start, Radau's never do.

A re-simulation (Monte Carlo, tracking, a sensitivity along the path) that interpolated the control
points otherwise — a spline through all of them, say — would integrate another control than the one
the solver optimized, and its mean would not be the nominal even where the dynamics are linear in
the uncertain parameter. A Result without a mesh (saved by another tool, or a kind that is not a
transcription) is interpolated linearly between its control points.

:func:`step_edges` cuts each mesh interval into equal integration steps, so that no step straddles a
jump, and :meth:`TranscribedSignal.on_steps` gives each step the values of its own interval at its
start, middle and end (the stage times of RK4).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from gamespec.result import Result


@dataclass(frozen=True)
class TranscribedSignal:
    """Signals held per interval of ``mesh``: ``coefficients`` (rows, intervals, degree+1) are the
    polynomial of each interval in its local time ``s = (t - mesh[k]) / (mesh[k+1] - mesh[k])``,
    highest power first."""

    mesh: np.ndarray
    coefficients: np.ndarray

    @property
    def rows(self) -> int:
        return self.coefficients.shape[0]

    def _evaluate(self, t: np.ndarray, interval: np.ndarray) -> np.ndarray:
        """Values (rows, len(t)) of interval ``interval[j]``'s polynomial at ``t[j]``."""
        start, end = self.mesh[interval], self.mesh[interval + 1]
        s = (t - start) / (end - start)
        coefficients = self.coefficients[:, interval, :]
        out = np.zeros((self.rows, len(t)))
        for power in range(coefficients.shape[2]):
            out = out * s + coefficients[:, :, power]
        return out

    def interval_of(self, t: np.ndarray) -> np.ndarray:
        """The interval holding each time: ``(t_k, t_{k+1}]`` (the first one from the mesh's start,
        the last one past its end), the interval whose last control point a node is (to rounding:
        :func:`_rounding`)."""
        inner = self.mesh[1:-1]
        return np.searchsorted(inner + _rounding(self.mesh), t, side="left").astype(int)

    def __call__(self, t: np.ndarray | float) -> np.ndarray:
        """Values (rows, len(t)) at times ``t``; at a mesh point, the interval it ends."""
        times = np.atleast_1d(np.asarray(t, dtype=float))
        return self._evaluate(times, self.interval_of(times))

    def at(self, t: float) -> list[float]:
        """The values at one time ``t`` (as :meth:`__call__`), in plain Python floats: what an ODE
        solver's right-hand side calls thousands of times."""
        inner, coefficients = self._scalar_tables
        k = bisect.bisect_left(inner, t)
        s = (t - self.mesh[k]) / (self.mesh[k + 1] - self.mesh[k])
        values = []
        for row in coefficients[k]:
            value = 0.0
            for c in row:
                value = value * s + c
            values.append(value)
        return values

    @cached_property
    def _scalar_tables(self) -> tuple[list[float], list[list[list[float]]]]:
        inner = (self.mesh[1:-1] + _rounding(self.mesh)).tolist()
        return inner, np.transpose(self.coefficients, (1, 0, 2)).tolist()

    def on_steps(self, edges: np.ndarray) -> np.ndarray:
        """Values (rows, steps, 3) at the start, middle and end of each step between ``edges``, each
        step's from its own interval (the one holding its middle): both sides of a jump are seen."""
        start, end = edges[:-1], edges[1:]
        middle = 0.5 * (start + end)
        interval = self.interval_of(middle)
        stages = [self._evaluate(times, interval) for times in (start, middle, end)]
        return np.stack(stages, axis=2)


def _rounding(mesh: np.ndarray) -> float:
    """How far a control point may sit from a mesh point it is on: ``t_k + h * 1`` need not round
    to ``t_{k+1}``."""
    return 1e-9 * float(np.ptp(mesh))


def _linear(times: np.ndarray, table: np.ndarray) -> TranscribedSignal:
    """Linear interpolation between the points: one interval per pair of points."""
    slopes = table[:, 1:] - table[:, :-1]
    return TranscribedSignal(times, np.stack([slopes, table[:, :-1]], axis=2))


def mesh_polynomials(mesh: np.ndarray, times: np.ndarray, table: np.ndarray) -> TranscribedSignal:
    """The polynomial through each mesh interval's own control points (see the module doc)."""
    eps = _rounding(mesh)
    closed = abs(times[0] - mesh[0]) <= eps
    intervals = len(mesh) - 1
    owned = []
    for k in range(intervals):
        low, high = mesh[k], mesh[k + 1]
        inside = times >= low - eps if closed else times > low + eps
        owned.append(np.flatnonzero(inside & (times <= high + eps)))
    if min(len(points) for points in owned) == 0:
        return _linear(times, table)
    degree = max(len(points) for points in owned) - 1
    coefficients = np.zeros((table.shape[0], intervals, degree + 1))
    for k, points in enumerate(owned):
        s = (times[points] - mesh[k]) / (mesh[k + 1] - mesh[k])
        vandermonde = np.vander(s, len(points))
        fitted = np.linalg.solve(vandermonde, table[:, points].T).T
        coefficients[:, k, degree + 1 - len(points) :] = fitted
    return TranscribedSignal(mesh, coefficients)


def transcribed_signal(result: Result, names: list[str]) -> TranscribedSignal:
    """The Result's controls (or grid inputs, ``arrays["input/<name>"]``) of these names as the
    transcription holds them (see the module doc)."""
    times = np.asarray(result.control_time if result.control_time is not None else result.time, dtype=float)
    rows = [result.controls[n] if n in result.controls else result.arrays[f"input/{n}"] for n in names]
    table = np.array(rows, dtype=float).reshape(len(names), -1)
    if times.size < 2:
        return TranscribedSignal(times[0] + np.array([-1.0, 1.0]), table[:, None, :1])
    mesh = result.arrays.get("control_mesh")
    if mesh is None:
        return _linear(times, table)
    return mesh_polynomials(np.asarray(mesh, dtype=float), times, table)


def step_edges(mesh: np.ndarray | None, t0: float, tf: float, steps: int) -> np.ndarray:
    """About ``steps`` integration steps over ``[t0, tf]``, each piece between the mesh points
    inside it cut into equal steps (at least one) in proportion to its length, so that no step
    crosses a mesh point."""
    inside = np.asarray([] if mesh is None else mesh, dtype=float)
    eps = _rounding(np.array([t0, tf]))
    breaks = np.concatenate([[t0], inside[(inside > t0 + eps) & (inside < tf - eps)], [tf]])
    lengths = np.diff(breaks)
    cuts = np.maximum(1, np.round(steps * lengths / (tf - t0))).astype(int)
    pieces = [np.linspace(a, b, c + 1)[:-1] for a, b, c in zip(breaks[:-1], breaks[1:], cuts, strict=True)]
    return np.concatenate([*pieces, [tf]])
