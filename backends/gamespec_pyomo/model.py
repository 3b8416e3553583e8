"""A :class:`~gamespec.ocp.transcription.Transcription` as a Pyomo model: the explicit collocation of
:mod:`gamespec.ocp.collocation`, row for row the NLP the CasADi backend builds, so both backends
solve the identical discretization.

Variables ``X[i, node]``, ``U[j, point]``, the design variables ``d[name]`` and the horizon ``T``
(time scaling ``t = t0 + tau * T``). The problem's parameters ``p[name]``, the grid inputs
``w[input, point]`` indexed by evaluation point and, when the final time is fixed, ``T`` are Vars
too, that the solve step fixes through equal bounds: an NL file holds a fixed Var's value as a
constant in its expressions but a bounded Var's value in its bounds segment, so the file is written
once and a re-solve rewrites only its bounds and start (:mod:`gamespec_pyomo.nlfile`); the solver
eliminates variables with equal bounds before it starts.
Constraints: the defects ``(D X - T W F(X, U, t)) / s_x = 0`` (s_x: the state scales), path
constraints at every evaluation point, boundary constraints over the end values and integral
constraints ``T q^T g``; objective ``Phi + T q^T L`` in minimization form. The ``scaling_factor``
Suffix (``1/scale``, written to the NL file as a suffix, which ripopt reads) gives the solver the
scaled variables the casadi backend gives IPOPT.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from functools import lru_cache
from typing import Any

import numpy as np

from gamespec.errors import UnsupportedFeature
from gamespec.ocp.transcription import Transcription
from gamespec.symbolic.grammar import FileFunction, Relation
from gamespec.symbolic.library import Library, LibraryAlgebra


def _minimum(a: Any, b: Any) -> Any:
    return 0.5 * (a + b - abs(a - b))


def _maximum(a: Any, b: Any) -> Any:
    return 0.5 * (a + b + abs(a - b))


def _refused(name: str) -> Callable[..., Any]:
    """A library entry that refuses ``name``: Pyomo's expressions have no such function, and ripopt
    differentiates the conditional (Expr_if) form that would emulate it wrongly."""

    def refuse(*args: Any) -> Any:
        raise UnsupportedFeature(
            f"backend 'pyomo' cannot take {name}: Pyomo's expressions have no {name}, and ripopt "
            "differentiates the conditional (Expr_if) form wrongly; use the casadi backend"
        )

    return refuse


TABLE_TOLERANCE = 1e-9
"""The largest error of a table's arithmetic form the backend takes, relative to the values' range
(:meth:`~gamespec.symbolic.truncated.TruncatedTable.error`, measured for each table)."""


@lru_cache(maxsize=64)
def _pyomo_table(table: FileFunction) -> Callable[..., Any]:
    """A table as arithmetic and ``abs`` (:mod:`gamespec.symbolic.truncated`), refused when its
    measured rounding exceeds :data:`TABLE_TOLERANCE`."""
    form = table.truncated  # type: ignore[attr-defined]
    error = form.error(table)
    if not error <= TABLE_TOLERANCE:
        raise UnsupportedFeature(
            f"backend 'pyomo' cannot take table {table.name!r}: its form in abs (no conditionals, "
            f"which ripopt differentiates wrongly) is off by {error:.1e} of the values' range, more than "
            f"{TABLE_TOLERANCE:g} (grid intervals of very different sizes); use the casadi backend"
        )
    return form  # type: ignore[no-any-return]


@lru_cache(maxsize=1)
def pyomo_library() -> Library:
    """Pyomo's intrinsic functions by gamespec's names (min/max through ``abs``, which the NL
    format has; no atan2, sign or heaviside: they are refused when a problem uses them) and the
    file's tables in arithmetic and ``abs`` (:func:`_pyomo_table`). One library per process, so
    that each model takes the problem's kept walks again
    (:meth:`~gamespec.symbolic.library.LibraryAlgebra.__eq__`)."""
    import pyomo.environ as pyo

    library = Library.from_namespace(
        pyo,
        atan2=_refused("atan2"),
        sign=_refused("sign"),
        heaviside=_refused("heaviside"),
        abs=abs,
        min=_minimum,
        max=_maximum,
    )
    return Library(library.functions, library.power, tables=_pyomo_table)


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


def _relation(rel: Relation, expr: Any) -> Any:
    """A Pyomo constraint body for ``lower <= expr <= upper`` (an equality when they coincide)."""
    if rel.is_equality:
        return expr == rel.lower
    return (_finite(rel.lower), expr, _finite(rel.upper))


def build_model(tr: Transcription, params: Mapping[str, float]) -> Any:
    """The Pyomo ``ConcreteModel`` of ``tr`` starting from ``params``, with a dual Suffix."""
    import pyomo.environ as pyo

    ocp, grid = tr.ocp, tr.grid
    D, W, q = grid.matrices
    k = len(grid.eval_index)
    m = pyo.ConcreteModel(name=tr.spec.name)
    m.p = pyo.Var(ocp.parameters, initialize=dict(params))
    m.w = pyo.Var(range(tr.n_w), range(k), initialize=0.0)
    m.X = pyo.Var(range(tr.n_x), range(grid.n_nodes), initialize=0.0)
    m.U = pyo.Var(range(tr.n_u), range(k), initialize=0.0)
    m.d = pyo.Var(ocp.design, initialize=0.0)
    m.T = pyo.Var(initialize=1.0)
    others = {n: m.p[n] for n in ocp.parameters} | {n: m.d[n] for n in ocp.design}
    algebra = LibraryAlgebra(pyomo_library())

    F = np.empty((tr.n_x, k), dtype=object)
    L = []
    path = []
    integrands = []
    for col, (node, tau) in enumerate(zip(grid.eval_index, grid.eval_tau, strict=True)):
        x = [m.X[i, int(node)] for i in range(tr.n_x)]
        u = [m.U[j, col] for j in range(tr.n_u)]
        w = [m.w[i, col] for i in range(tr.n_w)]
        terms = ocp.running_terms(ocp.running_values(x, u, w, tr.t0 + tau * m.T, others), algebra)
        F[:, col] = terms.dynamics
        L.append(terms.lagrange)
        path.append([_relation(r, r.expr) for r in terms.path])
        integrands.append(terms.integrands)
    n_path, n_int = len(ocp.running_structure.path), range(len(ocp.running_structure.integrands))

    sx, su = tr.compiled_scaling.states, tr.compiled_scaling.controls

    def defect(_m: Any, i: int, row: int) -> Any:
        """The defect row divided by its state's scale (:mod:`gamespec.ocp.scaling`)."""
        dx = sum(float(v / sx[i]) * m.X[i, int(c)] for c, v in _row(D, row))
        return dx - m.T * sum(float(v / sx[i]) * F[i, int(c)] for c, v in _row(W, row)) == 0

    m.defect = pyo.Constraint(range(tr.n_x), range(D.shape[0]), rule=defect)
    m.path = pyo.Constraint(range(n_path), range(k), rule=lambda _m, r, col: path[col][r])

    x_ends = ([m.X[i, 0] for i in range(tr.n_x)], [m.X[i, grid.n_nodes - 1] for i in range(tr.n_x)])
    ends = ocp.end_terms(ocp.end_values(x_ends, tr.end_controls(m.U), tr.t0 + m.T, others), algebra)
    interior = tr.interior.terms(m.X, others, algebra)
    boundary = [_relation(r, r.expr) for r in [*ends.boundary, *interior.constraints]]
    m.boundary = pyo.Constraint(range(len(boundary)), rule=lambda _m, r: boundary[r])
    integral = [m.T * sum(float(w) * terms[r] for w, terms in zip(q, integrands, strict=True)) for r in n_int]
    m.integral_value = pyo.Var(n_int, initialize=0.0)
    m.integral = pyo.Constraint(n_int, rule=lambda _m, r: m.integral_value[r] == integral[r])
    running = sum(float(w) * term for w, term in zip(q, L, strict=True))
    m.objective = pyo.Objective(expr=ends.mayer + m.T * running + tr.rate_penalty(m.U) + interior.misfit)
    m.dual = pyo.Suffix(direction=pyo.Suffix.IMPORT)
    m.scaling_factor = pyo.Suffix(direction=pyo.Suffix.EXPORT)
    for (i, _), var in m.X.items():
        m.scaling_factor[var] = 1.0 / sx[i]
    for (j, _), var in m.U.items():
        m.scaling_factor[var] = 1.0 / su[j]
    return m


def _row(matrix: Any, row: int) -> zip:
    """Column indices and values of one row of a CSR matrix."""
    lo, hi = matrix.indptr[row], matrix.indptr[row + 1]
    return zip(matrix.indices[lo:hi], matrix.data[lo:hi], strict=True)
