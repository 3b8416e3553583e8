"""Vectorized re-simulation of a solved open-loop control under many parameter values at once.

Classical RK4 with about ``steps`` steps over ``[t0, t_f]``, each mesh interval of the transcription
cut into equal steps (:func:`gamespec.ocp.control_signal.step_edges`), every sample in one NumPy
array (samples along the last axis), the control applied exactly as the transcription holds it (the
polynomial of each mesh interval, :mod:`gamespec.ocp.control_signal`), and the running cost
integrated as one more state. The dynamics are the file's SymPy
expressions evaluated on arrays by :func:`gamespec.symbolic.calculus.numeric_function` (no code is
generated, no Python call per sample).

When every sample follows the same path (an open loop whose dynamics, running cost and initial
state do not depend on the sampled parameters: chapter 6's obstacles of uncertain speed, eqs.
6.38-6.39), the path is integrated once, all steps in one call of a CasADi function (the RK4 step
of the same expressions, ``mapaccum``-ed over the steps), and only the path constraints are
evaluated per sample, for every step at once: the same numbers to rounding, without a Python
loop over the steps.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
import sympy as sp

from gamespec.ocp.control_signal import TranscribedSignal, step_edges, transcribed_signal
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.result import Result
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.language import TIME, symbol
from gamespec.symbolic.library import casadi_library
from gamespec.symbolic.translate import translate

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
    function = _numeric(tuple(exprs), tuple(values))
    return np.broadcast_to(function(*values.values()), (len(exprs), *shape))


@lru_cache(maxsize=256)
def _numeric(exprs: tuple[sp.Expr, ...], args: tuple[sp.Symbol, ...]) -> Callable[..., np.ndarray]:
    """:func:`numeric_function` of ``exprs`` in ``args``, recorded once per pair (a report
    evaluates the same terms on every re-solve of a compiled chain)."""
    return numeric_function(exprs, args)


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
    if feedback is None and _shared_path(ocp, x0, params):
        return _one_path(ocp, x0, params, t, stages, u_open, w_open, keep, tolerance)
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


def _shared_path(ocp: SymbolicOcp, x0: np.ndarray, params: Values) -> bool:
    """Whether every sample follows the same open-loop path: one initial state, and dynamics and
    running cost free of the sampled parameters (those given one value per sample)."""
    sampled = {p for p in ocp.p if np.size(params[p]) > 1}
    flow = [*ocp.dynamics, ocp.lagrange]
    depends = set().union(*(sp.sympify(e).free_symbols for e in flow)) & sampled
    return not depends and bool(np.all(x0 == x0[:, :1]))


def _one_path(
    ocp: SymbolicOcp,
    x0: np.ndarray,
    params: Values,
    t: np.ndarray,
    stages: np.ndarray,
    u_open: np.ndarray,
    w_open: np.ndarray,
    keep: int,
    tolerance: float,
) -> Trajectories:
    """:func:`rk4` for samples that share one path (:func:`_shared_path`): the path integrated once
    by :func:`_rk4_path`, the path constraints of every sample evaluated on it."""
    samples, n, m = x0.shape[1], len(ocp.x), len(ocp.u)
    h = np.diff(t)
    nominal = [float(np.ravel(params[p])[0]) for p in ocp.p]
    y0 = np.append(x0[:, 0], 0.0)
    path = _rk4_path(*_flow_key(ocp), len(h))(
        y0,
        u_open.transpose(2, 0, 1).reshape(3 * m, len(h)),
        w_open.transpose(2, 0, 1).reshape(3 * w_open.shape[0], len(h)),
        stages.T,
        h[None, :],
        np.repeat(np.array(nominal, dtype=float)[:, None], len(h), axis=1),
    )
    y = np.hstack([y0[:, None], np.asarray(path, dtype=float)])  # (n + 1, steps + 1)
    x_path = y[:n]
    squares = np.sum(u_open**2, axis=0)  # (steps, 3)
    energy = float(np.sum(h / 6 * (squares[:, 0] + 2 * squares[:, 1] + 2 * squares[:, 1] + squares[:, 2])))
    u_path = np.concatenate([u_open[:, :, 0], u_open[:, -1:, 2]], axis=1)  # at each step's start
    w_path = np.concatenate([w_open[:, :, 0], w_open[:, -1:, 2]], axis=1)
    violation, violated = _path_violation(ocp, x_path, u_path, w_path, t, params, samples, tolerance)
    X = np.repeat(x_path.T[:, :, None], keep, axis=2)
    U = np.repeat(u_path.T[:, :, None], keep, axis=2)
    final = np.repeat(x_path[:, -1:], samples, axis=1)
    running, energies = np.full(samples, y[n, -1]), np.full(samples, energy)
    return Trajectories(t, X, U, final, running, energies, violation, violated)


CHUNK = 1 << 16
"""Values (times × samples × constraints) of the path constraints evaluated in one NumPy call
(small enough to stay in the cache: larger calls are slower)."""


def _path_violation(
    ocp: SymbolicOcp,
    x: np.ndarray,
    u: np.ndarray,
    w: np.ndarray,
    t: np.ndarray,
    params: Values,
    samples: int,
    tolerance: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Each sample's largest path-constraint violation over the times ``t`` of one shared path
    ``x`` (n, len(t)) under ``u`` and ``w`` (the parameters per sample, broadcast along ``t``), and
    at each time the fraction of samples whose violation so far exceeds ``tolerance``
    (``Trajectories.violated``)."""
    violation, violated = np.zeros(samples), np.zeros(len(t))
    if not ocp.path:
        return violation, violated
    function = numeric_function([rel.expr for rel in ocp.path], [*ocp.p, *ocp.w, *ocp.x, *ocp.u, TIME])
    lower = np.array([rel.lower for rel in ocp.path])[:, None, None]
    upper = np.array([rel.upper for rel in ocp.path])[:, None, None]
    fixed = [np.reshape(params[p], (1, -1)) if np.size(params[p]) > 1 else params[p] for p in ocp.p]
    rows = max(1, CHUNK // (samples * len(ocp.path)))
    for start in range(0, len(t), rows):
        cut = slice(start, start + rows)
        along = [v[cut, None] for v in (*w, *x, *u, t)]
        g = np.broadcast_to(function(*fixed, *along), (len(ocp.path), len(t[cut]), samples))
        excess = np.maximum(lower - g, 0.0) + np.maximum(g - upper, 0.0)
        so_far = np.maximum.accumulate(np.maximum(excess.max(axis=0), violation), axis=0)
        violated[cut] = np.count_nonzero(so_far > tolerance, axis=1) / samples
        violation = so_far[-1]
    return violation, violated


Symbols = tuple[sp.Symbol, ...]


def _flow_key(ocp: SymbolicOcp) -> tuple[Symbols, Symbols, Symbols, Symbols, tuple[sp.Expr, ...]]:
    """The parameters, inputs, states, controls and flow (dynamics, signed running cost) of ``ocp``:
    what :func:`_rk4_path` is built from, hashable."""
    flow = tuple(sp.sympify(e) for e in [*ocp.dynamics, ocp.sign * ocp.lagrange])
    return tuple(ocp.p), tuple(ocp.w), tuple(ocp.x), tuple(ocp.u), flow


@lru_cache(maxsize=32)
def _rk4_path(p: Symbols, w: Symbols, x: Symbols, u: Symbols, flow: tuple[sp.Expr, ...], steps: int) -> Any:
    """:func:`_rk4_step` accumulated over ``steps`` steps (CasADi's ``mapaccum``): the state and
    running cost after each step; kept for the re-solves of the same problem."""
    return _rk4_step(p, w, x, u, flow).mapaccum(steps)


def _rk4_step(p: Symbols, w: Symbols, x: Symbols, u: Symbols, flow: tuple[sp.Expr, ...]) -> Any:
    """One RK4 step of the flow as a CasADi ``Function`` ``(y, u, w, t, h, p) → y⁺`` (``y`` the
    state and the running cost; ``u``, ``w`` the controls and inputs at the step's start, middle and
    end, stacked; ``t`` those three times), built from the same SymPy expressions as :func:`rk4`'s
    NumPy ones."""
    import casadi as ca

    library = casadi_library(ca)
    n, m, k = len(x), len(u), len(w)
    y, U, W = ca.SX.sym("y", n + 1), ca.SX.sym("u", 3 * m), ca.SX.sym("w", 3 * k)
    ts, h, P = ca.SX.sym("t", 3), ca.SX.sym("h"), ca.SX.sym("p", len(p))

    def f(state: Any, stage: int) -> Any:
        values = dict(zip(p, ca.vertsplit(P), strict=True))
        values |= dict(zip(w, [W[stage * k + i] for i in range(k)], strict=True))
        values |= dict(zip(x, ca.vertsplit(state[:n]), strict=True))
        values |= dict(zip(u, [U[stage * m + j] for j in range(m)], strict=True))
        values[TIME] = ts[stage]
        return ca.vertcat(*(translate(e, values, library) for e in flow))

    k1 = f(y, 0)
    k2 = f(y + h / 2 * k1, 1)
    k3 = f(y + h / 2 * k2, 1)
    k4 = f(y + h * k3, 2)
    return ca.Function("rk4_step", [y, U, W, ts, h, P], [y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)])


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
