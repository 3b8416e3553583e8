"""Checks of an OCP solution computed from the Result's arrays alone, never from the solver.

- ``max_defect``: each interval re-integrated with RK4 (``RK4_STEPS`` steps) from its first node
  under the interpolated control and grid inputs; the largest gap to the next interval's first node.
  Inputs are interpolated as the controls are and as the transcription sees them: through the
  interval's collocation points (the degree d-1 polynomial, Radau) or linearly between nodes
  (trapezoidal), so the check measures the discretization, not how a signal was tabulated.
- ``max_defect_relative``: the same gap divided by the state's scale ``max(1, max |x|)`` (what
  ``method.refine.tolerance`` is compared with).
- ``max_constraint_violation``: bounds, fixed end values, path, boundary, interior-point (``at:``)
  and integral constraints,
  the integrals re-integrated with the states (RK4, as the defects) rather than by the
  transcription's own quadrature, which cannot see an integrand between its points.
- ``control_swings/<control>``: total variation of the control over the range it spans; ``chattering``
  is 1 when one sweeps its range more than ``CHATTERING_SWINGS`` times (regularize it with
  ``method.control_rate_penalty``), else 0.
- ``hamiltonian_variation``: ``max |H - mean H|`` along the solution, with ``H = sign*L + lambda^T f
  + nu^T g`` from the costate estimates and the integral constraints' multipliers ``nu`` (integrands
  ``g``: the isoperimetric problem's augmented Hamiltonian, constant on an optimal arc). Left out,
  with the reason in ``metrics["checks_skipped"]``, where H need not be constant: explicit time in
  f, L, a path constraint or an integrand (``dH/dt = dH/dt|explicit``, e.g. a time-dependent obstacle),
  a grid input that enters f or L and varies along the grid (``dH/dt = dH/dw * dw/dt``), or no
  costate estimates (the trapezoidal scheme).
- ``hamiltonian_end_error``: ``max |H + dPhi/dt_f|`` on free-final-time problems where H is constant,
  since the transversality condition fixes the constant (``H = 0`` for minimum time, eqs. 2.22–2.23).

Each check with a tolerance (:data:`DEFAULT_TOLERANCES`, ``method.refine.tolerance`` for the relative
defect) gets a verdict (:func:`verdicts`); a NaN or infinite value (an overflowing re-integration)
fails, and mesh refinement splits the intervals where it occurs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from gamespec.ocp.compiled_checks import (
    end_terms,
    interior_constraints,
    mayer_names,
    point_values,
    reintegrate,
)
from gamespec.specs.ocp import INITIAL_TIME
from gamespec.symbolic.grammar import Relation, dependencies
from gamespec.symbolic.library import NUMPY, LibraryAlgebra

ARRAYS = LibraryAlgebra(NUMPY)
"""The problem's terms built straight from the file's text over NumPy arrays."""

if TYPE_CHECKING:
    from gamespec.ocp.transcription import Transcription

RK4_STEPS = 16
CHATTERING_SWINGS = 10.0
"""A control that sweeps its range more often than this (total variation over the range it spans)
chatters: a bang-bang or bang-singular profile sweeps it a few times, on every mesh."""
CONSTANT_SPAN = 1e-6
"""A control whose range is below this fraction of ``max(1, max |u|)`` is constant: an interior-point
solver leaves a control that sits on a bound about its tolerance inside it, and the noise of that
must not read as sweeps."""


@dataclass(frozen=True)
class Trajectory:
    """A transcribed solution: states ``X`` (n_x × nodes), controls ``U`` and grid inputs ``Win``
    (n_u, n_w × evaluation points), the horizon ``T``."""

    X: np.ndarray
    U: np.ndarray
    Win: np.ndarray
    T: float


def _point_values(tr: Transcription, sol: Trajectory, params: Mapping[str, float]) -> np.ndarray:
    """The running terms at the evaluation points (:func:`~gamespec.ocp.compiled_checks.point_values`:
    the dynamics (first ``n_x`` rows), the Lagrange integrand (row ``n_x``), the integral
    constraints' integrands, then the path constraints' expressions; ``params`` holds the design
    variables' values too)."""
    t_eval = tr.t0 + sol.T * tr.grid.eval_tau
    p = np.array([params[n] for n in [*tr.ocp.parameters, *tr.ocp.design]], dtype=float)
    return point_values(tr, sol.X[:, tr.grid.eval_index], sol.U, sol.Win, t_eval, p)


def control_basis(tr: Transcription, s: np.ndarray, degree: int | None = None) -> np.ndarray:
    """Weights (len(s) × points) interpolating the controls of an interval of ``degree`` (the
    first interval's when None) at local times ``s``."""
    grid = tr.grid
    if grid.scheme == "trapezoidal":
        return np.stack([1.0 - s, s], axis=1)
    pts = grid.local_points(int(grid.interval_degrees[0]) if degree is None else degree)[1:]
    basis = np.ones((len(s), len(pts)))
    for r, pr in enumerate(pts):
        for q, pq in enumerate(pts):
            if q != r:
                basis[:, r] *= (s - pq) / (pr - pq)
    return basis


def _per_interval(tr: Transcription, V: np.ndarray, chosen: np.ndarray) -> np.ndarray:
    """Values at the evaluation points (rows × n_eval) of the ``chosen`` intervals, all of one
    degree d, as (rows, chosen intervals, d points)."""
    grid = tr.grid
    if grid.scheme == "radau":
        first = grid.interval_start_index[chosen]
        d = int(grid.interval_degrees[chosen[0]])
        return V[:, first[:, None] + np.arange(d)[None, :]]
    return np.stack([V[:, chosen], V[:, chosen + 1]], axis=2)


@np.errstate(all="ignore")
def reintegration(
    tr: Transcription, sol: Trajectory, params: Mapping[str, float]
) -> tuple[np.ndarray, np.ndarray]:
    """Each interval re-integrated with RK4 from its first node, the integral constraints'
    integrands along with the states: per state and interval (n_x × intervals) the gap to the
    collocated state at the interval's end, and the integrals over the horizon (NaN where the
    re-integration overflows; the intervals of each degree together)."""
    grid = tr.grid
    n_int = len(tr.ocp.running_structure.integrands)
    gaps = np.empty((tr.n_x, grid.intervals))
    integrals = np.zeros(n_int)
    for degree in sorted(set(grid.interval_degrees.tolist())):
        chosen = np.flatnonzero(grid.interval_degrees == degree)
        gaps[:, chosen], pieces = _rk4(tr, sol, params, chosen, int(degree))
        integrals += np.sum(pieces, axis=1)
    return gaps, integrals


def interval_defects(tr: Transcription, sol: Trajectory, params: Mapping[str, float]) -> np.ndarray:
    """The gaps of :func:`reintegration` (what mesh refinement reads)."""
    return reintegration(tr, sol, params)[0]


def _rk4(
    tr: Transcription, sol: Trajectory, params: Mapping[str, float], chosen: np.ndarray, degree: int
) -> tuple[np.ndarray, np.ndarray]:
    """The gaps at the ends of the ``chosen`` intervals (all of ``degree``) and the integrals of the
    integrands over each of them (n_integrals × chosen): ``RK4_STEPS`` classical RK4 steps per
    interval, compiled once (:mod:`gamespec.ocp.compiled_checks`)."""
    X, T = sol.X, sol.T
    grid = tr.grid
    starts = grid.interval_start_index
    h = np.diff(grid.breaks)[chosen] * T
    t0 = tr.t0 + T * grid.breaks[chosen]
    Ui, Wi = _per_interval(tr, sol.U, chosen), _per_interval(tr, sol.Win, chosen)
    nx = tr.n_x
    n_int = len(tr.ocp.running_structure.integrands)
    y = np.vstack([X[:, starts[chosen]].astype(float), np.zeros((n_int, len(chosen)))])
    halves = np.arange(2 * RK4_STEPS + 1) / (2 * RK4_STEPS)
    bases = control_basis(tr, halves, degree)
    p = np.array([params[n] for n in [*tr.ocp.parameters, *tr.ocp.design]], dtype=float)
    y = reintegrate(tr, degree, RK4_STEPS, bases, y, Ui, Wi, h, t0, p)
    return np.abs(y[:nx] - X[:, starts[chosen + 1]]), y[nx:]


def state_scale(X: np.ndarray) -> np.ndarray:
    """Per state, ``max(1, max |x|)`` along the solution: what a defect is relative to."""
    return np.maximum(1.0, np.max(np.abs(X), axis=1, initial=0.0))


def relative_defects(tr: Transcription, sol: Trajectory, params: Mapping[str, float]) -> np.ndarray:
    """Per interval, the largest defect over the states relative to each state's scale."""
    gaps = interval_defects(tr, sol, params) / state_scale(sol.X)[:, None]
    return np.max(gaps, axis=0, initial=0.0)


DEFAULT_TOLERANCES = {"max_constraint_violation": 1e-6, "max_defect_relative": 1e-6, "chattering": 0.0}
"""What each check is held to when the file sets nothing: a constraint violation and a relative
defect at the level of IPOPT's default tolerance, and no chattering control."""


def check_tolerances(checks: Mapping[str, float | None], defect_tolerance: float | None) -> dict[str, float]:
    """The tolerance of each check present that has one (``method.refine.tolerance`` for the
    relative defect when the file sets one)."""
    tolerances = DEFAULT_TOLERANCES | (
        {"max_defect_relative": defect_tolerance} if defect_tolerance is not None else {}
    )
    return {name: float(tol) for name, tol in tolerances.items() if name in checks}


def verdicts(checks: Mapping[str, float | None], tolerances: Mapping[str, float]) -> dict[str, bool]:
    """Pass (True) or fail per check in ``tolerances``: its value is at most its tolerance; a value
    that could not be computed (None, NaN, an overflow) fails."""
    return {
        name: checks[name] is not None and bool(np.isfinite(checks[name]) and checks[name] <= tol)
        for name, tol in tolerances.items()
    }


def control_swings(U: np.ndarray) -> np.ndarray:
    """Per control, its total variation ``sum_k |u_{k+1} - u_k|`` over the evaluation points divided
    by the range it spans (0 for a constant control, one that spans less than
    :data:`CONSTANT_SPAN` of its magnitude): how many times it sweeps that range."""
    if U.shape[1] < 2:
        return np.zeros(U.shape[0])
    variation = np.sum(np.abs(np.diff(U, axis=1)), axis=1)
    span = np.ptp(U, axis=1)
    moving = span > CONSTANT_SPAN * np.maximum(1.0, np.max(np.abs(U), axis=1))
    return np.where(moving, variation / np.where(moving, span, 1.0), 0.0)


def _violation(values: np.ndarray, lower: np.ndarray | float, upper: np.ndarray | float) -> float:
    if np.size(values) == 0:
        return 0.0
    return float(max(np.max(lower - values, initial=0.0), np.max(values - upper, initial=0.0)))


def _relation_violation(rel: Relation, shape: tuple[int, ...]) -> float:
    v = np.broadcast_to(np.asarray(rel.expr, dtype=float), shape)
    return _violation(v, rel.lower, rel.upper)


def max_constraint_violation(
    tr: Transcription, sol: Trajectory, params: Mapping[str, float], integrals: np.ndarray | None = None
) -> float:
    """Largest violation of bounds (the design variables' too), fixed end values, path, boundary
    and integral constraints: the ``integrals`` given (re-integrated, :func:`reintegration`), else
    by the transcription's quadrature, which only sees the integrand at the collocation points (a
    hanging chain may bend steeply between them, its length uncounted)."""
    X, U, T = sol.X, sol.U, sol.T
    b = tr.bounds(params)
    worst = [_violation(X, b.x_lower, b.x_upper), _violation(U, b.u_lower, b.u_upper)]
    worst.append(_violation(np.array([T]), b.t_lower, b.t_upper))
    worst.append(_violation(np.array([params[n] for n in tr.ocp.design]), b.d_lower, b.d_upper))
    values = _point_values(tr, sol, params)
    structure = tr.ocp.running_structure
    first_path = tr.n_x + 1 + len(structure.integrands)
    worst += [
        _violation(row, r.lower, r.upper) for row, r in zip(values[first_path:], structure.path, strict=True)
    ]
    worst += [_relation_violation(r, ()) for r in end_terms(tr, _end_values(tr, X, U, T, params)).boundary]
    worst += [_relation_violation(r, ()) for r in interior_constraints(tr, X, params)]
    q = tr.grid.triplets[2]
    if integrals is None:
        integrals = [T * q @ row for row in values[tr.n_x + 1 : first_path]]
    for value, (lo, hi) in zip(integrals, tr.ocp.integral_bounds(params), strict=True):
        worst.append(_violation(np.array([value]), lo, hi))
    return float(np.max(worst))


def _end_values(
    tr: Transcription, X: np.ndarray, U: np.ndarray, T: float, params: Mapping[str, float]
) -> dict:
    return tr.ocp.end_values((X[:, 0], X[:, -1]), tr.end_controls(U), np.float64(tr.t0 + T), _arrays(params))


def _arrays(params: Mapping[str, float]) -> dict[str, np.float64]:
    """The parameter values as NumPy numbers, so that a term over them evaluates in NumPy (an
    infinity or NaN of a failed solve is a value, not an error as in the floats of
    :data:`~gamespec.symbolic.grammar.FLOATS`)."""
    return {n: np.float64(v) for n, v in params.items()}


def hamiltonian(
    tr: Transcription,
    sol: Trajectory,
    params: Mapping[str, float],
    lam: np.ndarray,
    integral_multipliers: np.ndarray | None = None,
) -> np.ndarray:
    """``H = sign*L + lambda^T f + nu^T g`` at the collocation points (eq. 2.22 in general form,
    augmented by the integral constraints' integrands ``g`` and their multipliers ``nu``)."""
    values = _point_values(tr, sol, params)
    nx = tr.n_x
    H = values[nx] + np.sum(lam * values[:nx], axis=0)
    if integral_multipliers is not None and len(integral_multipliers):
        n_int = len(tr.ocp.running_structure.integrands)
        H = H + np.asarray(integral_multipliers, dtype=float) @ values[nx + 1 : nx + 1 + n_int]
    return H


STEP = float(np.finfo(float).eps) ** (1 / 3)
"""The relative step of :func:`mayer_slope`'s central difference (the one that balances its
truncation error, h**2/6 times the third derivative, against its rounding error eps |Phi| / h)."""


def mayer_slope(tr: Transcription, ends: Mapping[str, float], name: str) -> float:
    """``dPhi/d name`` of the minimization form's Mayer term at the end values ``ends`` (by name):
    exactly 0 when the term does not depend on ``name``, else a central difference with step
    ``STEP max(1, |value|)`` (the term compiled once, :func:`~gamespec.ocp.compiled_checks.end_terms`)."""
    if name not in mayer_names(tr):
        return 0.0
    at = float(ends[name])
    h = STEP * max(1.0, abs(at))
    mayer = (end_terms(tr, {**ends, name: at + s}).mayer for s in (h, -h))
    return (next(mayer) - next(mayer)) / (2 * h)


def hamiltonian_end_value(tr: Transcription, ends: Mapping[str, float]) -> float:
    """``-dPhi/dt_f`` at the solution's end values: the constant value of H on an autonomous,
    free-final-time problem (transversality, e.g. eq. 2.23); with a fixed final time and a free
    initial one, ``+dPhi/dt_0`` (the Mayer term sees ``t_f = t_0 + T``: its slope in ``t_0`` at
    fixed ``t_f`` is the slope at fixed ``T`` less the slope in ``t_f``)."""
    if tr.spec.problem.time.free:
        return -mayer_slope(tr, ends, "t_f")
    return mayer_slope(tr, ends, INITIAL_TIME) - mayer_slope(tr, ends, "t_f")


def varying_hamiltonian(tr: Transcription, Win: np.ndarray) -> str | None:
    """Why H need not be constant along this solution (None when it must be): explicit time in the
    dynamics, the running cost, a path constraint or an integrand, or a grid input that enters f or
    L and varies on the grid."""
    if not tr.ocp.autonomous:
        return "the dynamics or the running cost depend on t explicitly"
    structure = tr.ocp.running_structure
    for kind, terms in (
        ("path constraint", [r.expr for r in structure.path]),
        ("integrand", structure.integrands),
    ):
        for number, term in enumerate(terms):
            if "t" in dependencies(term):
                return f"{kind} {number} depends on t explicitly (its multiplier makes H vary)"
    used = Win[tr.ocp.inputs_in_hamiltonian]
    if not np.all(used == used[:, :1]):
        return "a grid input that enters the dynamics or the running cost varies along the grid"
    return None


HAMILTONIAN_CHECKS = ("hamiltonian_variation", "hamiltonian_end_error")


@np.errstate(all="ignore")
def solution_checks(
    tr: Transcription,
    sol: Trajectory,
    params: Mapping[str, float],
    lam: np.ndarray | None,
    integral_multipliers: np.ndarray | None = None,
) -> tuple[dict[str, float | None], dict[str, str]]:
    """All checks that apply to this problem and solution (NaN where a value cannot be computed,
    e.g. a diverging re-integration of a failed solve), and the checks left out with the reason."""
    gaps, integrals = reintegration(tr, sol, params)
    checks: dict[str, float | None] = {
        "max_constraint_violation": max_constraint_violation(tr, sol, params, integrals),
    }
    checks["max_defect"] = float(np.max(gaps, initial=0.0))
    checks["max_defect_relative"] = float(np.max(gaps / state_scale(sol.X)[:, None], initial=0.0))
    if tr.n_u:
        swings = control_swings(sol.U)
        checks |= {f"control_swings/{n}": float(v) for n, v in zip(tr.ocp.controls, swings, strict=True)}
        checks["chattering"] = float(np.max(swings) > CHATTERING_SWINGS)
    applicable = HAMILTONIAN_CHECKS if tr.free_time else HAMILTONIAN_CHECKS[:1]
    if lam is None:
        reason = "no costate estimates (the trapezoidal scheme, or no multipliers from the solver)"
        return checks, dict.fromkeys(applicable, reason)
    varying = varying_hamiltonian(tr, sol.Win)
    if varying is not None:
        return checks, dict.fromkeys(applicable, f"H need not be constant: {varying}")
    H = hamiltonian(tr, sol, params, lam, integral_multipliers)
    checks["hamiltonian_variation"] = float(np.max(np.abs(H - H.mean())))
    if tr.free_time:
        end = hamiltonian_end_value(tr, _end_values(tr, sol.X, sol.U, sol.T, params))
        checks["hamiltonian_end_error"] = float(np.max(np.abs(H - end)))
    return checks, {}
