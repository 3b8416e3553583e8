"""Which expression of the file is not finite, and where (issue 25, item 7): when a solve ends with
a NaN or an infinity (IPOPT's ``Invalid_Number_Detected``, ripopt's evaluation errors), the NLP
solver can name only a row or a column of its own ("row 3, col 28"). The transcription knows which
expression of the file each row comes from, so :func:`non_finite_report` evaluates the file's
expressions themselves at the point the solver stopped at (or at the starting point): each
definition in its order, each state's derivative, the running cost, the path constraints and the
integrands at every evaluation point, then the Mayer term and the boundary constraints at the ends,
each with its derivatives in the states, controls and design variables (what the solver's Jacobian
and Hessian need: ``sqrt(vx**2 + vy**2)`` is 0 at rest but its derivative is 0/0). The first one
that is NaN or infinite is named with the time and the values it was evaluated at.

SymPy differentiates (the expressions as the transforms see them) and
:func:`~gamespec.symbolic.translate.translate` evaluates on NumPy arrays, all points at once; this
runs only after a failed solve.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gamespec.symbolic.library import NUMPY

if TYPE_CHECKING:
    from gamespec.ocp.transcription import Transcription


@dataclass(frozen=True)
class Point:
    """A transcribed trajectory at which to look: states at the nodes, controls at the evaluation
    points, the horizon, grid inputs and the parameter and design values by name."""

    X: np.ndarray
    U: np.ndarray
    T: float
    inputs: np.ndarray
    values: Mapping[str, float]


def _named_terms(tr: Transcription) -> Iterator[tuple[str, str, Any, bool]]:
    """``(label, text, SymPy expression, running)`` of every expression of the file in evaluation
    order; ``running``: evaluated along the trajectory (else at the ends)."""
    from gamespec.symbolic.language import SYMPY, symbol

    ocp, problem = tr.ocp, tr.spec.problem
    scope: dict[str, Any] = {n: symbol(n) for n in ocp.running_names}
    built = ocp.definitions(scope, SYMPY)
    for name, raw in problem.definitions.items():
        yield f"definition {name}", str(raw), built[name], True
    terms = ocp.running_terms(scope, SYMPY)
    for name, expr in zip(ocp.states, terms.dynamics, strict=True):
        yield f"the derivative of state {name}", str(problem.dynamics[name]), expr, True
    if problem.objective.lagrange not in (0, 0.0, "0"):
        yield "the running cost", str(problem.objective.lagrange), terms.lagrange, True
    texts = [
        *problem.path_constraints,
        *(f"{n} {k} bound {raw}" for n, k, raw in problem.time_varying_bounds()),
    ]
    for text, rel in zip(texts, terms.path, strict=True):
        yield "path constraint", text, rel.expr, True
    for c, expr in zip(problem.integral_constraints, terms.integrands, strict=True):
        yield "the integrand of integral constraint", str(c.integrand), expr, True
    ends = ocp.end_terms({n: symbol(n) for n in ocp.end_names}, SYMPY)
    if problem.objective.mayer not in (0, 0.0, "0"):
        yield "the Mayer term", str(problem.objective.mayer), ends.mayer, False
    for text, rel in zip(problem.boundary_constraints, ends.boundary, strict=True):
        yield "boundary constraint", text, rel.expr, False


def _running_values(tr: Transcription, at: Point) -> dict[str, Any]:
    ocp, grid = tr.ocp, tr.grid
    x = at.X[:, grid.eval_index]
    t = tr.t0 + at.T * grid.eval_tau
    values = ocp.running_values(list(x), list(at.U), list(at.inputs), t, dict(at.values))
    return {n: np.broadcast_to(np.asarray(v, dtype=float), t.shape) for n, v in values.items()}


def _end_values(tr: Transcription, at: Point) -> dict[str, Any]:
    ocp = tr.ocp
    first, last = tr.end_controls(at.U)
    x = (list(at.X[:, 0]), list(at.X[:, -1]))
    values = ocp.end_values(x, (first, last), tr.t0 + at.T, dict(at.values))
    return {n: np.atleast_1d(np.asarray(v, dtype=float)) for n, v in values.items()}


def _first_bad(expr: Any, values: Mapping[str, np.ndarray], wrt: list[str]) -> tuple[str, int] | None:
    """``(what, index)``: the first of the value and the derivatives in ``wrt`` that is not finite
    somewhere, and the first point where it is not."""
    import sympy as sp

    from gamespec.symbolic.language import symbol
    from gamespec.symbolic.translate import translate

    by_symbol = {symbol(n): v for n, v in values.items()}
    names = {str(s) for s in expr.free_symbols}
    candidates = [("its value", expr)] + [
        (f"its derivative in {n}", sp.diff(expr, symbol(n))) for n in wrt if n in names
    ]
    shape = next(iter(values.values())).shape
    for what, term in candidates:
        with np.errstate(all="ignore"):
            try:
                value = np.broadcast_to(np.asarray(translate(term, by_symbol, NUMPY), dtype=float), shape)
            except (ArithmeticError, ValueError, TypeError):
                return what, 0
        bad = ~np.isfinite(value)
        if bad.any():
            return what, int(np.argmax(bad))
    return None


def non_finite_report(tr: Transcription, at: Point) -> str | None:
    """One sentence naming the first expression of the file (in evaluation order) whose value or
    derivative is NaN or infinite at ``at``, with the time and the values it depends on; None when
    every one is finite there."""
    ocp = tr.ocp
    running = _running_values(tr, at)
    ends = _end_values(tr, at)
    wrt_running = [*ocp.states, *ocp.controls, *ocp.design]
    wrt_ends = [*(f"{n}_{e}" for e in "0f" for n in [*ocp.states, *ocp.controls]), *ocp.design, "t_f"]
    for label, text, expr, along in _named_terms(tr):
        values, wrt = (running, wrt_running) if along else (ends, wrt_ends)
        found = _first_bad(expr, values, wrt)
        if found is None:
            continue
        what, index = found
        used = sorted(str(s) for s in expr.free_symbols if str(s) in values)
        shown = ", ".join(f"{n} = {float(np.ravel(values[n])[index]):.6g}" for n in used)
        where = f"t = {float(running['t'][index]):.6g}" if along else "the ends"
        return f"{label} ({text}): {what} is not finite at {where} ({shown})"
    return None
