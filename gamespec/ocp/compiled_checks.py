"""The checks' per-interval RK4 re-integration compiled once as a CasADi ``Function``.

:func:`gamespec.ocp.checks.reintegration` integrates each mesh interval from its first node with
``RK4_STEPS`` classical RK4 steps under the interval's control polynomial (and its grid inputs),
the integral constraints' integrands along with the states. Evaluated by a tape of NumPy calls,
each of the ``4 · RK4_STEPS`` stages costs one pass over every operation of the dynamics — on
small problems re-solved often (a receding-horizon game's thousand NLPs) that was most of a
solve's time. Here the whole re-integration of one interval is one CasADi SX function of the
interval's start ``y0``, its control and input points, its length ``h``, its start time ``t0``
and the parameter values, built once per transcription and interval degree from the running
terms' function at one point, and mapped over the intervals: one call of compiled code per check.
That function and the end-point terms' are built from the file's expressions
(:class:`~gamespec.symbolic.library.LibraryAlgebra` over CasADi) when the model is compiled
(:func:`prepare`), so no solve walks text (issue 27, item 3). The arithmetic is the same as the
NumPy route's, so the numbers agree to rounding.
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from gamespec.ocp.symbolic import EndTerms
from gamespec.symbolic.grammar import Relation
from gamespec.symbolic.library import LibraryAlgebra, casadi_library

if TYPE_CHECKING:
    from gamespec.ocp.transcription import Transcription


_FUNCTIONS: weakref.WeakKeyDictionary[Transcription, dict[tuple[int, ...], Any]] = weakref.WeakKeyDictionary()
"""Each live transcription's compiled re-integrations by (degree, steps) and their maps by
(degree, steps, intervals): a compiled model keeps one transcription, so one build serves every
re-solve."""


def rk4_function(tr: Transcription, degree: int, steps: int, bases: np.ndarray) -> Any:
    """``(y0, U, W, h, t0, p) → y(t0 + h)`` for one interval of ``degree`` (``steps`` RK4 steps;
    ``bases[half]`` weights the interval's control points at local time ``half / (2 steps)``, the
    same for every call with this degree and step count), built on first use."""
    functions = _FUNCTIONS.setdefault(tr, {})
    if (degree, steps) not in functions:
        functions[degree, steps] = _build(tr, degree, steps, bases)
    return functions[degree, steps]


def prepare(tr: Transcription) -> None:
    """Build the checks' compiled functions of ``tr`` from the file's expressions now, when the
    model is compiled (the running terms and the end-point terms, each walked once): the re-
    integrations of every interval degree are built from the running function later, and no solve
    walks text (issue 27, item 3)."""
    _running_function(tr)
    _end_function(tr)
    _interior_function(tr)


def _running_function(tr: Transcription) -> Any:
    """The running terms at one point (:func:`point_values`' rows), built once per transcription."""
    functions = _FUNCTIONS.setdefault(tr, {})
    if () not in functions:
        functions[()] = _point_function(tr)
    return functions[()]


def _build(tr: Transcription, degree: int, steps: int, bases: np.ndarray) -> Any:
    import casadi as ca

    ocp = tr.ocp
    running = _running_function(tr)
    nx, nu, nw = len(ocp.states), len(ocp.controls), len(ocp.inputs)
    n_p = len(ocp.parameters) + len(ocp.design)
    n_int = len(ocp.running_structure.integrands)
    points = bases.shape[1]
    y0 = ca.SX.sym("y0", nx + n_int)
    U, W = ca.SX.sym("U", nu, points), ca.SX.sym("W", nw, points)
    h, t0, p = ca.SX.sym("h"), ca.SX.sym("t0"), ca.SX.sym("p", n_p)
    ds = 1.0 / steps

    def f(y: Any, half: int) -> Any:
        u = U @ bases[half] if nu else ca.SX(0, 1)
        w = W @ bases[half] if nw else ca.SX(0, 1)
        rows = running(y[:nx], u, w, p, t0 + half * ds / 2 * h)
        return ca.vertcat(rows[:nx], rows[nx + 1 : nx + 1 + n_int])

    y = y0
    for step in range(steps):
        k1 = f(y, 2 * step)
        k2 = f(y + 0.5 * ds * h * k1, 2 * step + 1)
        k3 = f(y + 0.5 * ds * h * k2, 2 * step + 1)
        k4 = f(y + ds * h * k3, 2 * step + 2)
        y = y + ds * h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return ca.Function(f"rk4_degree_{degree}", [y0, U, W, h, t0, p], [y])


def _split(v: Any, rows: int) -> list[Any]:
    import casadi as ca

    return list(ca.vertsplit(v)) if rows else []


def reintegrate(
    tr: Transcription,
    degree: int,
    steps: int,
    bases: np.ndarray,
    y0: np.ndarray,
    U: np.ndarray,
    W: np.ndarray,
    h: np.ndarray,
    t0: np.ndarray,
    p: np.ndarray,
) -> np.ndarray:
    """The ends ``(n_y, k)`` of the ``k`` intervals' re-integrations from ``y0`` (n_y, k) under their
    control and input points ``U`` (n_u, k, d), ``W`` (n_w, k, d), lengths ``h`` and starts ``t0``."""
    k = y0.shape[1]
    functions = _FUNCTIONS.setdefault(tr, {})
    if (degree, steps, k) not in functions:
        functions[degree, steps, k] = rk4_function(tr, degree, steps, bases).map(k)
    mapped = functions[degree, steps, k]
    d = bases.shape[1]
    out = mapped(y0, U.reshape(U.shape[0], k * d), W.reshape(W.shape[0], k * d), h[None, :], t0[None, :], p)
    return np.asarray(out, dtype=float).reshape(y0.shape[0], k)


def point_values(
    tr: Transcription, x: np.ndarray, u: np.ndarray, w: np.ndarray, t: np.ndarray, p: np.ndarray
) -> np.ndarray:
    """The running terms at ``k`` points (columns of the states ``x``, controls ``u``, grid inputs
    ``w`` and times ``t``; ``p`` the parameter and design values): the dynamics (first ``n_x``
    rows), the Lagrange integrand (``sign`` applied), the integral constraints' integrands and the
    path constraints' expressions (:attr:`~gamespec.ocp.symbolic.SymbolicOcp.running_structure`'s
    order, their bounds there), one CasADi SX function of one point built once per transcription
    and mapped over the points."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    k = t.size
    functions = _FUNCTIONS.setdefault(tr, {})
    if (k,) not in functions:
        functions[k,] = _running_function(tr).map(k)
    out = functions[k,](x, u, w, p, t[None, :])
    return np.asarray(out, dtype=float).reshape(-1, k)


def _point_function(tr: Transcription) -> Any:
    import casadi as ca

    ocp = tr.ocp
    algebra = LibraryAlgebra(casadi_library(ca))
    n_p = len(ocp.parameters) + len(ocp.design)
    x, u, w = ca.SX.sym("x", tr.n_x), ca.SX.sym("u", tr.n_u), ca.SX.sym("w", tr.n_w)
    p, t = ca.SX.sym("p", n_p), ca.SX.sym("t")
    slots = [*_split(x, tr.n_x), *_split(u, tr.n_u), *_split(w, tr.n_w), *_split(p, n_p), t]
    terms = ocp.running_terms(dict(zip(ocp.running_names, slots, strict=True)), algebra)
    rows = [*terms.dynamics, terms.lagrange, *terms.integrands, *(r.expr for r in terms.path)]
    return ca.Function("point", [x, u, w, p, t], [ca.vertcat(*rows)])


@dataclass(frozen=True)
class _EndFunction:
    """The end-point terms as one CasADi function of the end values, the boundary relations it
    evaluates (their bounds) and the names the Mayer term depends on."""

    function: Any
    boundary: list[Relation]
    mayer_names: frozenset[str]


_END_FUNCTIONS: weakref.WeakKeyDictionary[Transcription, _EndFunction] = weakref.WeakKeyDictionary()
"""Each live transcription's compiled end-point terms."""


def end_terms(tr: Transcription, values: Mapping[str, Any]) -> EndTerms:
    """The end-point terms (:class:`~gamespec.ocp.symbolic.EndTerms`: the Mayer term, ``sign``
    applied, and the boundary constraints) at the end ``values`` (by
    :attr:`~gamespec.ocp.symbolic.SymbolicOcp.end_names`), one CasADi SX function built once per
    transcription: a re-solve walks no text (issue 27, item 3)."""
    compiled = _end_function(tr)
    point = np.array([float(values[n]) for n in tr.ocp.end_names])
    mayer, found = (np.asarray(v, dtype=float).reshape(-1) for v in compiled.function(point))
    boundary = [Relation(v, r.lower, r.upper) for v, r in zip(found, compiled.boundary, strict=True)]
    return EndTerms(mayer=float(mayer[0]), boundary=boundary)


def mayer_names(tr: Transcription) -> frozenset[str]:
    """The end names the Mayer term depends on."""
    return _end_function(tr).mayer_names


def _end_function(tr: Transcription) -> _EndFunction:
    import casadi as ca

    if tr in _END_FUNCTIONS:
        return _END_FUNCTIONS[tr]
    names = tr.ocp.end_names
    ends = ca.SX.sym("ends", len(names))
    slots = _split(ends, len(names))
    algebra = LibraryAlgebra(casadi_library(ca))
    terms = tr.ocp.end_terms(dict(zip(names, slots, strict=True)), algebra)
    mayer = ca.SX(terms.mayer)
    rows = [ca.SX(r.expr) for r in terms.boundary]
    function = ca.Function("ends", [ends], [mayer, ca.vertcat(*rows) if rows else ca.SX(0, 1)])
    used = frozenset(n for n, slot in zip(names, slots, strict=True) if ca.depends_on(mayer, slot))
    _END_FUNCTIONS[tr] = _EndFunction(function, terms.boundary, used)
    return _END_FUNCTIONS[tr]


@dataclass(frozen=True)
class _InteriorFunction:
    """The interior-point constraints (``at:``, ``x(t=5)`` in boundary constraints;
    :mod:`gamespec.ocp.events`) as one CasADi function of the state nodes and the parameter and
    design values, and the relations it evaluates (their bounds)."""

    function: Any
    constraints: list[Relation]


_INTERIOR_FUNCTIONS: weakref.WeakKeyDictionary[Transcription, _InteriorFunction] = weakref.WeakKeyDictionary()
"""Each live transcription's compiled interior-point constraints."""


def interior_constraints(tr: Transcription, X: np.ndarray, params: Mapping[str, float]) -> list[Relation]:
    """The interior-point constraints at the state nodes ``X`` (unscaled) and the parameter and
    design values ``params`` (by name), by one CasADi function built when the model is compiled
    (:func:`prepare`): a solve walks no text (issue 27, item 3)."""
    compiled = _interior_function(tr)
    if not compiled.constraints:
        return []
    p = np.array([float(params[n]) for n in [*tr.ocp.parameters, *tr.ocp.design]])
    found = np.asarray(compiled.function(np.asarray(X, dtype=float), p), dtype=float).reshape(-1)
    return [Relation(v, r.lower, r.upper) for v, r in zip(found, compiled.constraints, strict=True)]


def _interior_function(tr: Transcription) -> _InteriorFunction:
    import casadi as ca

    if tr in _INTERIOR_FUNCTIONS:
        return _INTERIOR_FUNCTIONS[tr]
    problem = tr.spec.problem
    constraints: list[Relation] = []
    function = None
    if problem.at or problem.measurements is not None or problem.inline_points():
        names = [*tr.ocp.parameters, *tr.ocp.design]
        X, p = ca.SX.sym("X", tr.n_x, tr.grid.n_nodes), ca.SX.sym("p", len(names))
        others = dict(zip(names, _split(p, len(names)), strict=True))
        constraints = tr.interior.terms(X, others, LibraryAlgebra(casadi_library(ca))).constraints
        rows = [ca.SX(r.expr) for r in constraints]
        function = ca.Function("interior", [X, p], [ca.vertcat(*rows) if rows else ca.SX(0, 1)])
    _INTERIOR_FUNCTIONS[tr] = _InteriorFunction(function, constraints)
    return _INTERIOR_FUNCTIONS[tr]
