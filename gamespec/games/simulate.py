"""The true system (eq. 7.2 at the true parameter values) driven by the players' open-loop controls.

A control tabulated at a transcription's evaluation points is what the transcription makes of it
between them (:mod:`gamespec.ocp.control_signal`): on each Radau interval the polynomial through
the interval's collocation points (a constant for degree 1, which makes the collocation of
state-independent dynamics the discrete model of eqs. 7.27–7.29), linear between nodes for the
trapezoidal scheme; held at its end values outside the horizon.

The dynamics are compiled once per game (:class:`Dynamics`, from the SymPy forms of
:mod:`gamespec.games.expressions`): CasADi's CVODES integrates one piece of time in which every
control is one polynomial (rtol 1e-11, atol 1e-12: the tolerances of the SciPy DOP853 integration it
replaced), and the pieces of a call (between the requested times and the control intervals'
breaks, so no piece crosses a jump of a control) are chained into one CasADi ``Function`` per
number of pieces: advancing the true system over a step is one call of compiled code.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gamespec.ocp.collocation import Grid
from gamespec.ocp.control_signal import TranscribedSignal, mesh_polynomials
from gamespec.specs.ocp import MethodSpec
from gamespec.symbolic.language import symbol
from gamespec.symbolic.library import casadi_library
from gamespec.symbolic.translate import translate

if TYPE_CHECKING:
    from gamespec.games.equilibrium import GameModel
    from gamespec.games.expressions import GameExpressions

RTOL, ATOL = 1e-11, 1e-12
"""CVODES's relative and absolute tolerances."""


def true_parameters(model: GameModel) -> dict[str, float]:
    """The game's parameter values with every uncertain one at its true value."""
    return dict(model.parameters) | {n: u.actual for n, u in model.game.problem.uncertain.items()}


def grid_of(method: MethodSpec) -> Grid:
    return Grid(
        method.scheme, method.intervals, method.degree if method.scheme == "radau" else 1, method.grading
    )


@dataclass(frozen=True)
class ControlPlan:
    """Controls by name as the transcription holds them (see module doc): ``signal`` on the mesh
    of the horizon ``[start, start + horizon]``, its rows in the order of ``names``."""

    names: list[str]
    signal: TranscribedSignal

    @classmethod
    def on_grid(
        cls, grid: Grid, values: Mapping[str, np.ndarray], start: float, horizon: float
    ) -> ControlPlan:
        """The controls ``values`` (one per evaluation point of ``grid`` over ``[start, start +
        horizon]``)."""
        names = list(values)
        table = np.array([np.asarray(values[c], dtype=float) for c in names]).reshape(len(names), -1)
        mesh = start + horizon * grid.breaks
        return cls(names, mesh_polynomials(mesh, start + horizon * grid.eval_tau, table))

    @property
    def mesh(self) -> np.ndarray:
        return self.signal.mesh

    def at(self, t: float) -> dict[str, float]:
        """The controls at time ``t`` (held at the ends' values outside the horizon)."""
        clamped = min(max(t, float(self.mesh[0])), float(self.mesh[-1]))
        return dict(zip(self.names, self.signal(clamped)[:, 0].tolist(), strict=True))

    def pieces(self, edges: np.ndarray, names: list[str]) -> np.ndarray:
        """Per piece between ``edges`` (columns) the polynomial coefficients of the controls
        ``names`` in its interval's local time (rows: control by control, highest power first), then
        the piece's start ``s0`` and length ``c`` in that local time, its start time and length."""
        start, end = edges[:-1], edges[1:]
        interval = self.signal.interval_of(0.5 * (start + end))
        width = self.mesh[interval + 1] - self.mesh[interval]
        rows = [self.names.index(n) for n in names]
        coefficients = self.signal.coefficients[rows][:, interval, :]
        stacked = np.transpose(coefficients, (0, 2, 1)).reshape(-1, len(start))
        s0 = (start - self.mesh[interval]) / width
        return np.vstack([stacked, s0, (end - start) / width, start, end - start])


class Dynamics:
    """The game's dynamics compiled once (see module doc); :meth:`advance` integrates them."""

    def __init__(self, expressions: GameExpressions, controls: list[str]) -> None:
        self.expressions = expressions
        self.states = list(expressions.dynamics)
        self.controls = controls
        self._integrators: dict[int, Any] = {}
        self._chains: dict[tuple[int, int], Any] = {}

    def _integrator(self, width: int) -> Any:
        """CVODES over one piece in its own time ``σ ∈ [0, 1]``, for controls of ``width``
        coefficients: ``dx/dσ = L f(x, u(clip(s0 + c σ, 0, 1)), a + L σ)``."""
        if width not in self._integrators:
            import casadi as ca

            n_x, n_u, n_p = len(self.states), len(self.controls), len(self.expressions.parameters)
            x, sigma = ca.SX.sym("x", n_x), ca.SX.sym("sigma")
            p = ca.SX.sym("p", n_p + n_u * width + 4)
            s0, c, a, length = (p[n_p + n_u * width + i] for i in range(4))
            s = ca.fmin(ca.fmax(s0 + c * sigma, 0.0), 1.0)
            u = []
            for j in range(n_u):
                value = 0.0
                for power in range(width):
                    value = value * s + p[n_p + j * width + power]
                u.append(value)
            values = {symbol(n): p[i] for i, n in enumerate(self.expressions.parameters)}
            values |= {symbol(n): x[i] for i, n in enumerate(self.states)}
            values |= {symbol(n): u[j] for j, n in enumerate(self.controls)}
            values[symbol("t")] = a + length * sigma
            library = casadi_library(ca)
            f = ca.vertcat(*(translate(self.expressions.dynamics[n], values, library) for n in self.states))
            dae = {"x": x, "p": p, "t": sigma, "ode": length * f}
            options = {
                "abstol": ATOL,
                "reltol": RTOL,
                "max_num_steps": 100000,
                "disable_internal_warnings": True,
            }
            self._integrators[width] = ca.integrator("true_system", "cvodes", dae, 0.0, 1.0, options)
        return self._integrators[width]

    def _chain(self, width: int, pieces: int) -> Any:
        """``(x0, params, P) → X``: the states at the ends of ``pieces`` pieces in a row (columns),
        the piece ``k`` driven by column ``k`` of ``P`` (:meth:`ControlPlan.pieces`)."""
        if (width, pieces) not in self._chains:
            import casadi as ca

            step = self._integrator(width)
            n_x, n_p = len(self.states), len(self.expressions.parameters)
            x0, params = ca.MX.sym("x0", n_x), ca.MX.sym("params", n_p)
            plan = ca.MX.sym("plan", len(self.controls) * width + 4, pieces)
            x, ends = x0, []
            for k in range(pieces):
                x = step(x0=x, p=ca.vertcat(params, plan[:, k]))["xf"]
                ends.append(x)
            self._chains[width, pieces] = ca.Function("advance", [x0, params, plan], [ca.horzcat(*ends)])
        return self._chains[width, pieces]

    def advance(
        self,
        x0: np.ndarray,
        params: np.ndarray,
        plan: ControlPlan,
        t0: float,
        duration: float,
        breaks: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """States (rows) from ``x0`` at ``t0`` over ``duration`` at ``t0``, the times ``breaks``
        inside and ``t0 + duration`` (the times, the states); NaN rows after a failed integration."""
        end = t0 + duration
        times = np.unique(np.clip(np.concatenate([[t0, end], breaks]), t0, end))
        eps = 1e-9 * duration
        mesh = plan.mesh[(plan.mesh > t0 + eps) & (plan.mesh < end - eps)]
        jumps = mesh[np.min(np.abs(mesh[:, None] - times[None, :]), axis=1) > eps]
        edges = np.union1d(times, jumps)
        columns = plan.pieces(edges, self.controls)
        width = plan.signal.coefficients.shape[2]
        try:
            out = self._chain(width, edges.size - 1)(x0, params, columns)
            rows = np.asarray(out, dtype=float).T
        except RuntimeError:
            rows = np.full((edges.size - 1, len(self.states)), np.nan)
        kept = np.isin(edges[1:], times)
        return times, np.vstack([np.asarray(x0, dtype=float)[None, :], rows[kept]])


class TrueSystem:
    """The game's compiled dynamics at given parameter values."""

    def __init__(self, dynamics: Dynamics, parameters: Mapping[str, float]) -> None:
        self.dynamics = dynamics
        self.states = dynamics.states
        self.params = np.array([float(parameters[n]) for n in dynamics.expressions.parameters])

    def advance(
        self, x0: Mapping[str, float], plan: ControlPlan, t0: float, duration: float, breaks: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """States from ``x0`` at ``t0`` over ``duration`` under ``plan``, integrated piece by piece
        between the absolute times ``breaks``: the times (one per piece end, ``t0`` first) and
        states (rows)."""
        x = np.array([x0[s] for s in self.states], dtype=float)
        return self.dynamics.advance(x, self.params, plan, t0, duration, breaks)
