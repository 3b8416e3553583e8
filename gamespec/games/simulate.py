"""The true system (eq. 7.2 at the true parameter values) driven by the players' open-loop controls.

A control tabulated at a transcription's evaluation points is what the transcription makes of it
between them: on each Radau interval the polynomial through the interval's collocation points (a
constant for degree 1, which makes the collocation of state-independent dynamics the discrete model
of eqs. 7.27–7.29), linear between nodes for the trapezoidal scheme. The dynamics are integrated
by an adaptive Runge–Kutta method that stops at every interval break, so the integration error is
far below the transcription's.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING

import numpy as np
from scipy.integrate import solve_ivp

from gamespec.ocp.collocation import Grid
from gamespec.specs.differential_game import DifferentialGameSpec
from gamespec.specs.ocp import MethodSpec
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.language import parse, symbol

if TYPE_CHECKING:
    from gamespec.games.equilibrium import GameModel

Signal = Callable[[float], float]


def true_parameters(model: GameModel) -> dict[str, float]:
    """The game's parameter values with every uncertain one at its true value."""
    return dict(model.parameters) | {n: u.actual for n, u in model.game.problem.uncertain.items()}


def grid_of(method: MethodSpec) -> Grid:
    return Grid(
        method.scheme, method.intervals, method.degree if method.scheme == "radau" else 1, method.grading
    )


def control_signal(grid: Grid, values: np.ndarray, start: float, horizon: float) -> Signal:
    """The control ``values`` (one per evaluation point of ``grid`` over ``[start, start + horizon]``)
    as a function of absolute time (see module doc); held constant outside the horizon."""
    values = np.asarray(values, dtype=float)
    tau_eval = grid.eval_tau
    if grid.scheme != "radau":
        return lambda t: float(np.interp((t - start) / horizon, tau_eval, values))
    d = grid.degree
    breaks = grid.breaks
    coefficients = [
        np.polyfit(tau_eval[k * d : (k + 1) * d], values[k * d : (k + 1) * d], d - 1)
        for k in range(grid.intervals)
    ]

    def signal(t: float) -> float:
        tau = min(max((t - start) / horizon, 0.0), 1.0)
        k = int(np.clip(np.searchsorted(breaks, tau, side="left") - 1, 0, grid.intervals - 1))
        return float(np.polyval(coefficients[k], tau))

    return signal


class TrueSystem:
    """The game's dynamics as a NumPy function of (states, controls, t) at given parameter values."""

    def __init__(self, game: DifferentialGameSpec, parameters: Mapping[str, float]) -> None:
        p = game.problem
        self.states = list(p.states)
        self.controls = [c for pl in p.players.values() for c in pl.controls]
        names = [*p.parameters, *p.uncertain, *self.states, *self.controls, "t"]
        table = {n: symbol(n) for n in names}
        rates = [parse(p.dynamics[s], table) for s in self.states]
        self.params = [float(parameters[n]) for n in [*p.parameters, *p.uncertain]]
        self._f = numeric_function(rates, [table[n] for n in names])

    def rate(self, t: float, x: np.ndarray, u: np.ndarray) -> np.ndarray:
        return np.asarray(self._f(*self.params, *x, *u, t), dtype=float).ravel()

    def advance(
        self,
        x0: Mapping[str, float],
        controls: Mapping[str, Signal],
        t0: float,
        duration: float,
        breaks: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray]:
        """States from ``x0`` at ``t0`` over ``duration``, integrated piece by piece between the
        absolute times ``breaks``: the times (one per piece end, ``t0`` first) and states (rows)."""
        x = np.array([x0[s] for s in self.states], dtype=float)
        times = [t0]
        rows = [x]
        edges = np.unique(np.clip(np.concatenate([[t0, t0 + duration], breaks]), t0, t0 + duration))
        for a, b in itertools.pairwise(edges):
            inside = 1e-9 * (b - a)

            def rhs(t, y, lo=a + inside, hi=b - inside):
                return self.rate(t, y, [controls[c](min(max(t, lo), hi)) for c in self.controls])

            sol = solve_ivp(rhs, (a, b), x, method="DOP853", rtol=1e-11, atol=1e-12)
            x = sol.y[:, -1]
            times.append(b)
            rows.append(x)
        return np.array(times), np.array(rows)
