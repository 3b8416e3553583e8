"""Vectorized re-simulation of a solved open-loop control under many parameter values at once.

Classical RK4 on a uniform grid of ``steps`` steps over ``[t0, t_f]``, every sample in one NumPy
array (samples along the last axis), the control interpolated linearly between the Result's control
points, and the running cost integrated as one more state. The dynamics are the file's SymPy
expressions evaluated by :func:`gamespec.symbolic.translate.translate` on arrays (no code is
generated, no Python call per sample).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np
import sympy as sp

from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.result import Result
from gamespec.symbolic.language import TIME, symbol
from gamespec.symbolic.translate import NUMPY, translate

Values = Mapping[sp.Symbol, np.ndarray | float]
ControlLaw = Callable[[float, np.ndarray, int], np.ndarray]
"""``(t, x (n, samples), step) -> u (m, samples)``: the control applied at time t."""


@dataclass(frozen=True)
class Trajectories:
    """Per grid time and sample: states ``x`` (steps+1, n, samples) and controls ``u`` (steps+1, m,
    samples); the accumulated running cost ``running`` (samples,) and control energy ∫Σu² ``energy``."""

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    running: np.ndarray
    energy: np.ndarray


def open_loop(result: Result, controls: list[str]) -> Callable[[float], np.ndarray]:
    """The Result's control as a function of time (linear between its control points)."""
    tc = np.asarray(result.control_time if result.control_time is not None else result.time)
    table = np.array([np.asarray(result.controls[c], dtype=float) for c in controls]).reshape(len(controls), -1)

    def u(t: float) -> np.ndarray:
        return np.array([np.interp(t, tc, row) for row in table])

    return u


def evaluate(exprs: list[sp.Expr], values: Values, shape: tuple[int, ...]) -> np.ndarray:
    """The expressions on arrays, stacked (len(exprs), *shape)."""
    return np.array([np.broadcast_to(translate(e, values, NUMPY), shape) for e in exprs], dtype=float)


def rk4(
    ocp: SymbolicOcp,
    x0: np.ndarray,
    law: ControlLaw,
    params: Values,
    t0: float,
    tf: float,
    steps: int,
    dynamics: list[sp.Expr] | None = None,
) -> Trajectories:
    """Integrate ``dynamics`` (default: the file's) from ``x0`` (n, samples) under ``law``.

    The law is evaluated at the start of each step and at the RK4 stage times it is asked for, so an
    open-loop law is exact in time and a feedback law sees the state at the step's start (a
    zero-order hold of the feedback over one fine step).
    """
    f = ocp.dynamics if dynamics is None else dynamics
    states, controls = ocp.x, ocp.u
    samples = x0.shape[1]
    lagrange = ocp.sign * ocp.lagrange
    h = (tf - t0) / steps
    t = t0 + h * np.arange(steps + 1)
    X = np.empty((steps + 1, len(states), samples))
    U = np.empty((steps + 1, len(controls), samples))
    X[0] = x0
    running = np.zeros(samples)
    energy = np.zeros(samples)

    def rhs(tk: float, x: np.ndarray, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        values = dict(params)
        values.update(zip(states, x, strict=True))
        values.update(zip(controls, u, strict=True))
        values[TIME] = tk
        dx = evaluate(f, values, (samples,))
        cost = evaluate([lagrange], values, (samples,))[0]
        return dx, cost, np.sum(u**2, axis=0)

    for k in range(steps):
        tk, x = t[k], X[k]
        u1 = law(tk, x, k)
        u2 = law(tk + h / 2, x, k)
        u4 = law(tk + h, x, k)
        U[k] = u1
        k1, c1, e1 = rhs(tk, x, u1)
        k2, c2, e2 = rhs(tk + h / 2, x + h / 2 * k1, u2)
        k3, c3, e3 = rhs(tk + h / 2, x + h / 2 * k2, u2)
        k4, c4, e4 = rhs(tk + h, x + h * k3, u4)
        X[k + 1] = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        running += h / 6 * (c1 + 2 * c2 + 2 * c3 + c4)
        energy += h / 6 * (e1 + 2 * e2 + 2 * e3 + e4)
    U[-1] = law(t[-1], X[-1], steps)
    return Trajectories(t, X, U, ocp.sign * running, energy)


def end_values(ocp: SymbolicOcp, x: np.ndarray, tf: float, params: Values) -> dict[sp.Symbol, np.ndarray]:
    """The end symbols ``<state>_0``, ``<state>_f``, ``t_f`` and the parameters, from trajectories."""
    values: dict[sp.Symbol, np.ndarray | float] = dict(params)
    values.update(zip(ocp.x0, x[0], strict=True))
    values.update(zip(ocp.xf, x[-1], strict=True))
    values[symbol("t_f")] = tf
    return values


def cost(ocp: SymbolicOcp, run: Trajectories, params: Values) -> np.ndarray:
    """The file's objective (its own sense) of each sample: Mayer term plus the integrated Lagrange."""
    values = end_values(ocp, run.x, float(run.t[-1]), params)
    mayer = evaluate([ocp.sign * ocp.mayer], values, run.running.shape)[0]
    return mayer + run.running


def path_violation(ocp: SymbolicOcp, run: Trajectories, params: Values) -> np.ndarray:
    """Largest violation of the path constraints (eq. 6.2b) over the grid, per sample (0 if none)."""
    steps, _, samples = run.x.shape
    worst = np.zeros(samples)
    if not ocp.path:
        return worst
    values: dict[sp.Symbol, np.ndarray | float] = dict(params)
    values.update(zip(ocp.x, np.moveaxis(run.x, 1, 0), strict=True))
    values.update(zip(ocp.u, np.moveaxis(run.u, 1, 0), strict=True))
    values[TIME] = run.t[:, None]
    for rel in ocp.path:
        g = np.broadcast_to(translate(rel.expr, values, NUMPY), (steps, samples))
        excess = np.maximum(rel.lower - g, 0.0) + np.maximum(g - rel.upper, 0.0)
        worst = np.maximum(worst, excess.max(axis=0))
    return worst
