"""Interior points of a transcription: the states at fixed times inside the horizon, as linear
combinations of the state nodes (the collocation polynomial of the interval that holds the time),
and the terms over them — the ``at:`` constraints and the least-squares misfit of ``measurements:``
— in any algebra of :mod:`gamespec.symbolic.grammar` (the CasADi NLP adds them to its end-point
rows and cost, the checks evaluate them over the Result's arrays).

A time on a mesh break belongs to the interval that ends there (its polynomial reaches it; the
states are continuous, so the next interval's start node has the same value).
"""

from __future__ import annotations

import ast
import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from gamespec.ocp.collocation import Grid
from gamespec.symbolic.grammar import (
    Algebra,
    Relation,
    at_time_name,
    expression,
    relation,
    taken,
    taken_relation,
)

Weights = tuple[np.ndarray, np.ndarray]
"""Node indices and weights of a state's value at one time (:func:`node_weights`)."""

if TYPE_CHECKING:
    from gamespec.ocp.transcription import Transcription
    from gamespec.specs.ocp import OptimalControlSpec

BREAK_GAP = 1e-9
"""A mesh break this close to an event's normalized time is the event's break (none is added)."""


def with_event_breaks(grid: Grid, spec: OptimalControlSpec) -> Grid:
    """``grid`` with a mesh break at each ``at:`` time (normalized) that is not one already: an
    interior-point constraint makes the costates jump there and the control kink or jump, which no
    interval's polynomial holds inside it. The measurement times are not breaks (the states are
    smooth through them). A grid given by its mesh or per-interval degrees is kept as given."""
    problem = spec.problem
    if not problem.at and not problem.inline_points():
        return grid
    params = problem.parameter_values()
    t_final = problem.evaluate(params).t_final
    events, _ = problem.interior_times(params)
    t0 = problem.time.origin
    taus = [(t - t0) / (t_final - t0) for t in events]
    breaks = list(grid.breaks)
    for tau in taus:
        if min(abs(tau - b) for b in breaks) > BREAK_GAP:
            breaks.append(tau)
    if len(breaks) == len(grid.breaks):
        return grid
    mesh = tuple(sorted(breaks))
    return dataclasses.replace(grid, intervals=len(mesh) - 1, mesh=mesh)


def node_weights(grid: Grid, tau: float) -> tuple[np.ndarray, np.ndarray]:
    """The node indices and weights with ``x(tau) = sum_j weights[j] X[:, nodes[j]]``: the Lagrange
    basis of the interval holding ``tau`` (in normalized time) at its local time."""
    breaks = grid.breaks
    k = int(np.clip(np.searchsorted(breaks, tau, side="left") - 1, 0, grid.intervals - 1))
    degree = int(grid.interval_degrees[k])
    local = grid.local_points(degree)
    s = (tau - breaks[k]) / (breaks[k + 1] - breaks[k])
    weights = np.ones(len(local))
    for r, pr in enumerate(local):
        for q, pq in enumerate(local):
            if q != r:
                weights[r] *= (s - pq) / (pr - pq)
    start = int(grid.interval_start_index[k])
    return start + np.arange(len(local)), weights


def states_at(X: Any, nodes: np.ndarray, weights: np.ndarray, n_x: int) -> list[Any]:
    """Each state's value ``sum_j weights[j] X[i, nodes[j]]`` (``X`` a NumPy array or a CasADi
    matrix)."""
    return [sum(float(w) * X[i, int(j)] for j, w in zip(nodes, weights, strict=True)) for i in range(n_x)]


@dataclass(frozen=True)
class InteriorTerms:
    """The boundary constraints that name states at fixed times (``x(t=5)``), then the ``at:``
    constraints (in the order of the file), and the measurements' weighted sum of squared residuals
    (0 without measurements)."""

    constraints: list[Relation]
    misfit: Any


@dataclass(frozen=True)
class InteriorPoints:
    """The interior points of a transcription, their node weights computed once (the horizon is
    fixed: the times are fixed in normalized time too)."""

    tr: Transcription

    @cached_property
    def _weights(self) -> tuple[list[Weights], list[Weights], dict[float, Weights]]:
        """The node weights of the ``at:`` times, of the measurement times and of the times that
        boundary constraints name (``x(t=5)``), by time."""
        tr = self.tr
        params = tr.ocp.parameter_values()
        _, tf, _ = tr.ocp.final_time(params)
        events, measured = tr.spec.problem.interior_times(params)
        span = tf - tr.t0
        at = len(tr.spec.problem.at)
        return (
            [node_weights(tr.grid, (t - tr.t0) / span) for t in events[:at]],
            [node_weights(tr.grid, (t - tr.t0) / span) for t in measured],
            {t: node_weights(tr.grid, (t - tr.t0) / span) for t in events[at:]},
        )

    def _inline(self, X: Any, base: Mapping[str, Any], algebra: Algebra) -> list[Relation]:
        """The boundary constraints that name states at fixed times, over those values, the states'
        end values, the final time and ``base``."""
        tr = self.tr
        problem = tr.spec.problem
        inline = problem.inline_points()
        if not inline:
            return []
        scope = dict(base)
        for time, (nodes, weights) in self._weights[2].items():
            values = states_at(X, nodes, weights, tr.n_x)
            scope |= {at_time_name(x, time): v for x, v in zip(tr.ocp.states, values, strict=True)}
        last = tr.grid.n_nodes - 1
        for i, x in enumerate(tr.ocp.states):
            scope |= {f"{x}_0": X[i, 0], f"{x}_f": X[i, last]}
        scope["t_f"] = tr.ocp.final_time(tr.ocp.parameter_values())[0]
        return self._relations([problem.boundary_constraints[i] for i in sorted(inline)], scope, algebra)

    def _relations(self, texts: list[str], values: Mapping[str, Any], algebra: Algebra) -> list[Relation]:
        """The constraints ``texts`` over ``values`` (by name) in ``algebra``: each text walked once
        per algebra and names, for every mesh of the problem
        (:meth:`~gamespec.ocp.symbolic.SymbolicOcp.kept_relation`; issue 27, item 3)."""
        ocp = self.tr.ocp
        found = []
        for text in texts:
            kept = ocp.kept_relation(text, list(values), algebra)
            if kept is None:
                found.append(relation(text, dict(values) | ocp.functions, algebra))
            else:
                found.append(taken_relation(kept, values, text))
        return found

    def terms(self, X: Any, others: Mapping[str, Any], algebra: Algebra) -> InteriorTerms:
        """The terms over the state nodes ``X`` (unscaled) and the parameters and design variables
        ``others`` (by name), built in ``algebra``."""
        tr = self.tr
        problem = tr.spec.problem
        events, measured, _ = self._weights
        base = dict(others)
        constraints = self._inline(X, base, algebra)
        for event, (nodes, weights) in zip(problem.at, events, strict=True):
            scope = base | dict(zip(tr.ocp.states, states_at(X, nodes, weights, tr.n_x), strict=True))
            constraints += self._relations(event.constraints, scope, algebra)
        misfit: Any = algebra.number(0.0)
        data = problem.measurements
        if data is not None:
            rows = data.weight_rows()
            for i, (nodes, weights) in enumerate(measured):
                scope = base | dict(zip(tr.ocp.states, states_at(X, nodes, weights, tr.n_x), strict=True))
                for key, values in data.values.items():
                    kept = tr.ocp.kept_expression(key, list(scope), algebra)
                    value = (
                        expression(key, scope | tr.ocp.functions, algebra)
                        if kept is None
                        else taken(kept, scope, key)
                    )
                    residual = algebra.binary(ast.Sub, value, algebra.number(values[i]))
                    square = algebra.binary(ast.Mult, residual, residual)
                    misfit = algebra.binary(
                        ast.Add, misfit, algebra.binary(ast.Mult, algebra.number(rows[key][i]), square)
                    )
        return InteriorTerms(constraints, misfit)
