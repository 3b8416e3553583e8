"""Vectorized re-simulation of a solved open-loop control under many parameter values at once.

Classical RK4 with about ``steps`` steps over ``[t0, t_f]``, each mesh interval of the transcription
cut into equal steps (:func:`gamespec.ocp.control_signal.step_edges`), every sample in one NumPy
array (samples along the last axis), the control applied exactly as the transcription holds it (the
polynomial of each mesh interval, :mod:`gamespec.ocp.control_signal`), and the running cost
integrated as one more state. The dynamics are the file's SymPy
expressions evaluated on arrays by :func:`gamespec.symbolic.calculus.numeric_function` (no code is
generated, no Python call per sample).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import sympy as sp

from gamespec.ocp.control_signal import TranscribedSignal, step_edges, transcribed_signal
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.result import Result
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.language import TIME, symbol

Values = Mapping[sp.Symbol, np.ndarray | float]
Feedback = Callable[[int, np.ndarray], np.ndarray]
"""``(step, x (n, samples)) -> Δu (m, samples)``: a correction added to the open-loop control."""


@dataclass(frozen=True)
class Trajectories:
    """The grid ``t``; states ``x`` and controls ``u`` (steps+1, n or m, kept samples) of the first
    ``keep`` samples; per sample the final state ``final`` (n, samples), the integrated running cost
    ``running`` (the file's Lagrange term, in its own sense), the control energy ∫Σu² ``energy``
    and the largest path-constraint violation ``violation``; at each time of ``t`` the fraction of
    all samples whose violation so far exceeds the tolerance :func:`rk4` was given, ``violated``
    (the probability of a violation by then: the collision probability along the path)."""

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    final: np.ndarray
    running: np.ndarray
    energy: np.ndarray
    violation: np.ndarray
    violated: np.ndarray


def evaluate(exprs: list[sp.Expr], values: Values, shape: tuple[int, ...]) -> np.ndarray:
    """The expressions with each symbol of ``values`` given its value, stacked (len(exprs), *shape)."""
    function = numeric_function(exprs, list(values))
    return np.broadcast_to(function(*values.values()), (len(exprs), *shape))


DENSE = 20
"""Points per gap of a Result's time grid on which :func:`dense_integral` integrates."""


def values_at(result: Result, ocp: SymbolicOcp, t: np.ndarray) -> dict[sp.Symbol, np.ndarray | float]:
    """The Result's parameters, states (linear between its points) and controls
    (as the transcription holds them) at times ``t``, by symbol."""
    values: dict[sp.Symbol, np.ndarray | float] = {symbol(k): v for k, v in result.parameters.items()}
    time = np.asarray(result.time)
    values |= {symbol(k): np.interp(t, time, np.asarray(v)) for k, v in result.states.items()}
    if ocp.controls:
        values |= dict(zip(ocp.u, transcribed_signal(result, ocp.controls)(t), strict=True))
    values[TIME] = t
    return values


def dense_integral(result: Result, ocp: SymbolicOcp, integrand: sp.Expr) -> float:
    """``∫ integrand dt`` along the Result by the trapezoid rule on :data:`DENSE` points per gap of
    its time grid: independent of the collocation's quadrature (which sees the integrand at the
    collocation points only) and of the mesh (the file's or a refined one)."""
    time = np.asarray(result.time)
    steps = time[:-1, None] + np.diff(time)[:, None] * (np.arange(DENSE) / DENSE)[None, :]
    t = np.append(steps.ravel(), time[-1])
    return float(np.trapezoid(evaluate([integrand], values_at(result, ocp, t), t.shape)[0], t))


def rk4(
    ocp: SymbolicOcp,
    x0: np.ndarray,
    controls: TranscribedSignal,
    params: Values,
    t0: float,
    tf: float,
    steps: int,
    keep: int | None = None,
    inputs: TranscribedSignal | None = None,
    feedback: Feedback | None = None,
    tolerance: float = 0.0,
) -> Trajectories:
    """Integrate the file's dynamics from ``x0`` (n, samples) under the open-loop ``controls`` (plus
    ``feedback``, when given) and the grid ``inputs`` (when the problem has some); keep the
    trajectories of the first ``keep`` samples (all when None).

    The steps follow the controls' mesh (about ``steps`` of them, none across a mesh point); the
    open-loop signals are tabulated once at each step's RK4 stage times, from the step's own mesh
    interval; the feedback sees the state at the start of each step and is held over it (a
    zero-order hold). ``tolerance`` is the violation above which a sample counts as violating
    (``Trajectories.violated``).
    """
    samples = x0.shape[1]
    keep = samples if keep is None else min(keep, samples)
    n, m = len(ocp.x), len(ocp.u)
    t = step_edges(controls.mesh, t0, tf, steps)
    h = np.diff(t)
    stages = np.stack([t[:-1], t[:-1] + h / 2, t[1:]], axis=1)
    u_open = controls.on_steps(t).reshape(m, len(h), 3)
    w_open = inputs.on_steps(t) if inputs else np.empty((0, len(h), 3))
    X = np.empty((len(t), n, keep))
    U = np.empty((len(t), m, keep))
    running, energy, violation = np.zeros(samples), np.zeros(samples), np.zeros(samples)
    violated = np.zeros(len(t))
    args = [*ocp.p, *ocp.w, *ocp.x, *ocp.u, TIME]
    flow = numeric_function([*ocp.dynamics, ocp.sign * ocp.lagrange], args)
    path = numeric_function([rel.expr for rel in ocp.path], args)
    lower = np.array([[rel.lower] for rel in ocp.path])
    upper = np.array([[rel.upper] for rel in ocp.path])
    fixed = [params[p] for p in ocp.p]

    def at(
        function: Callable[..., np.ndarray], rows: int, k: int, stage: int, x: np.ndarray, u: np.ndarray
    ) -> np.ndarray:
        signals = list(w_open[:, k, stage])
        return np.broadcast_to(function(*fixed, *signals, *x, *u, stages[k, stage]), (rows, samples))

    def rhs(k: int, stage: int, x: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        values = at(flow, n + 1, k, stage, x, u)
        return values[:n], values[n], np.sum(u**2, axis=0)

    def record(index: int, k: int, stage: int, x: np.ndarray, u: np.ndarray) -> None:
        X[index], U[index] = x[:, :keep], np.broadcast_to(u, (m, samples))[:, :keep]
        if ocp.path:
            g = at(path, len(ocp.path), k, stage, x, u)
            excess = np.maximum(lower - g, 0.0) + np.maximum(g - upper, 0.0)
            np.maximum(violation, excess.max(axis=0), out=violation)
            violated[index] = np.count_nonzero(violation > tolerance) / samples

    x = x0
    for k, hk in enumerate(h):
        correction = np.zeros((m, 1)) if feedback is None else feedback(k, x)
        u1, u2, u4 = (u_open[:, k, stage, None] + correction for stage in range(3))
        record(k, k, 0, x, u1)
        k1, c1, e1 = rhs(k, 0, x, u1)
        k2, c2, e2 = rhs(k, 1, x + hk / 2 * k1, u2)
        k3, c3, e3 = rhs(k, 1, x + hk / 2 * k2, u2)
        k4, c4, e4 = rhs(k, 2, x + hk * k3, u4)
        x = x + hk / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        running += hk / 6 * (c1 + 2 * c2 + 2 * c3 + c4)
        energy += hk / 6 * (e1 + 2 * e2 + 2 * e3 + e4)
    last = len(h) - 1
    correction = np.zeros((m, 1)) if feedback is None else feedback(len(h), x)
    record(len(h), last, 2, x, u_open[:, last, 2, None] + correction)
    return Trajectories(t, X, U, x, running, energy, violation, violated)


def end_values(
    ocp: SymbolicOcp, x0: np.ndarray, xf: np.ndarray, tf: float, params: Values
) -> dict[sp.Symbol, np.ndarray | float]:
    """The end symbols ``<state>_0``, ``<state>_f``, ``t_f`` and the parameters."""
    values: dict[sp.Symbol, np.ndarray | float] = dict(params)
    values.update(zip(ocp.x0, x0, strict=True))
    values.update(zip(ocp.xf, xf, strict=True))
    values[symbol("t_f")] = tf
    return values


def cost(ocp: SymbolicOcp, x0: np.ndarray, run: Trajectories, params: Values) -> np.ndarray:
    """The file's objective (its own sense) of each sample: Mayer term plus the integrated Lagrange."""
    values = end_values(ocp, x0, run.final, float(run.t[-1]), params)
    mayer = evaluate([ocp.sign * ocp.mayer], values, run.running.shape)[0]
    return mayer + run.running
