"""Adaptive h-refinement of a collocation mesh on the solver-independent defect estimate (the loop of
GPOPS-II and dymos, in its simplest form): solve, split every interval whose defect relative to the
state scale exceeds ``method.refine.tolerance`` into two halves, re-solve on the new mesh from the
last solution, until no interval does or ``max_iterations`` refinements were made.

The model is rebuilt for each mesh (its NLP changes size) by the backend's own model class, so the
loop is the same for every collocation backend; the history goes to ``metrics["refinement"]``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from gamespec.ocp.checks import Trajectory, relative_defects
from gamespec.result import Result

if TYPE_CHECKING:
    from gamespec.backend.collocation import CollocationModel
    from gamespec.ocp.transcription import Transcription


def trajectory_of(tr: Transcription, result: Result) -> tuple[Trajectory, dict[str, float]]:
    """The transcribed solution in a Result, and the parameter values with the design variables."""
    X = np.array([result.states[n] for n in tr.ocp.states])
    U = np.array([result.controls[n] for n in tr.ocp.controls]).reshape(tr.n_u, -1)
    Win = np.array([result.arrays[f"input/{n}"] for n in tr.ocp.inputs]).reshape(tr.n_w, U.shape[1])
    values = dict(result.parameters) | result.metrics.get("design", {})
    return Trajectory(X, U, Win, float(result.t_final) - tr.t0), values


def split(breaks: np.ndarray, marked: np.ndarray) -> list[float]:
    """``breaks`` with the midpoint of every marked interval added."""
    mids = 0.5 * (breaks[:-1] + breaks[1:])[marked]
    return sorted({*breaks.tolist(), *mids.tolist()})


def _entry(tr: Transcription, result: Result) -> dict[str, Any]:
    return {
        "intervals": tr.grid.intervals,
        "variables": int(tr.grid.n_nodes * tr.n_x + len(tr.grid.eval_index) * tr.n_u),
        "status": result.status.value,
        "objective": result.objective,
        "max_defect_relative": result.checks.get("max_defect_relative"),
        "iterations": result.iterations,
        "solve_time_s": result.solve_time_s,
    }


def refined(
    model: CollocationModel,
    first: Result,
    parameters: Mapping[str, float] | None,
    inputs: Any,
) -> Result:
    """Refine from ``first`` (a solve of ``model``) until the relative defect meets the tolerance;
    the last Result, with ``metrics["refinement"]`` (one entry per mesh) and
    ``metrics["refinement_converged"]``."""
    options = model.tr.spec.method.refine
    current, result = model, first
    history = [_entry(current.tr, result)]
    for _ in range(options.max_iterations):
        if not result.ok:
            break
        sol, values = trajectory_of(current.tr, result)
        marked = relative_defects(current.tr, sol, values) > options.tolerance
        if not marked.any():
            break
        mesh = split(current.tr.grid.breaks, marked)
        method = current.tr.spec.method.model_copy(update={"mesh": mesh, "intervals": len(mesh) - 1})
        spec = current.tr.spec.model_copy(update={"method": method})
        current = type(model)(spec, model.options)
        result = current.solve_once(parameters, guess=result, inputs=inputs)
        history.append(_entry(current.tr, result))
    defect = result.checks.get("max_defect_relative")
    converged = bool(result.ok and defect is not None and defect <= options.tolerance)
    metrics = result.metrics | {"refinement": history, "refinement_converged": converged}
    return result.model_copy(update={"metrics": metrics})
