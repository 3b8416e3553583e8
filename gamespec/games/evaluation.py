"""A player's payoff at a given joint strategy, under the transcription its best response is solved on.

A best response's Result is a trajectory at ``(BR_p, s_{-p})``; a Nash gap also needs each player's
payoff at the returned point ``s`` itself, where no solver ran. Here the states of ``s`` are those
of the collocation equations of the player's own model (``D X − T W F(X, U, W, t) = 0`` with the
initial node fixed, :mod:`gamespec.ocp.collocation`), solved by Newton's method with the controls
and the grid inputs held, and the payoff is the transcription's own objective ``Φ(ends) + T qᵀL``
(eq. 7.1 as the NLP states it, without the control-rate penalty, as the Result's objective), so that
``J_p(s) − J_p(BR_p, s_{-p})`` compares two numbers of the same discrete problem.

Both are CasADi ``Function``\\ s built once per transcription (the defects, their Newton
``rootfinder`` with the exact Jacobian, and the payoff), from the same terms the NLP is built from
(:meth:`~gamespec.ocp.symbolic.SymbolicOcp.running_terms` over CasADi): one call of compiled code
per evaluation.
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from gamespec.ocp.transcription import Transcription
from gamespec.symbolic.library import LibraryAlgebra, casadi_library

DEFECT_TOLERANCE = 1e-10
"""Largest collocation defect, relative to ``max(1, max |x|)``, accepted for the states of a point."""
NEWTON_TOLERANCE = 1e-13
"""The largest defect (absolute) at which Newton's method stops."""


@dataclass(frozen=True)
class PointFunctions:
    """A transcription's compiled defects ``(z, q) → D X − T W F`` (z the states after the initial
    node, row by row; q = [x0; vec(U); vec(Win); T; params]), their Newton root ``(z0, q) → z`` and
    the payoff ``(X, U, Win, T, params) → J`` (the player's own sense)."""

    defects: Any
    root: Any
    payoff: Any


_FUNCTIONS: weakref.WeakKeyDictionary[Transcription, PointFunctions] = weakref.WeakKeyDictionary()


def point_functions(tr: Transcription) -> PointFunctions:
    """The compiled functions of ``tr`` (see :class:`PointFunctions`), built on first use."""
    if tr not in _FUNCTIONS:
        _FUNCTIONS[tr] = _build(tr)
    return _FUNCTIONS[tr]


def _build(tr: Transcription) -> PointFunctions:
    import casadi as ca

    ocp, grid = tr.ocp, tr.grid
    algebra = LibraryAlgebra(casadi_library(ca))
    n_x, n_u, n_w, nodes = tr.n_x, tr.n_u, tr.n_w, grid.n_nodes
    names = [*ocp.parameters, *ocp.design]
    k = grid.eval_tau.size
    z = ca.SX.sym("z", n_x * (nodes - 1))
    x0, U, Win = ca.SX.sym("x0", n_x), ca.SX.sym("U", n_u, k), ca.SX.sym("W", n_w, k)
    T, p = ca.SX.sym("T"), ca.SX.sym("p", len(names))
    X = ca.horzcat(x0, ca.reshape(z, nodes - 1, n_x).T)
    others = dict(zip(names, ca.vertsplit(p), strict=True))

    def rows(M: Any, j: int, count: int) -> list[Any]:
        return [M[i, j] for i in range(count)]

    F, L = [], []
    for j, (node, tau) in enumerate(zip(grid.eval_index, grid.eval_tau, strict=True)):
        values = ocp.running_values(
            rows(X, int(node), n_x), rows(U, j, n_u), rows(Win, j, n_w), tr.t0 + T * float(tau), others
        )
        terms = ocp.running_terms(values, algebra)
        F.append(ca.vertcat(*terms.dynamics))
        L.append(terms.lagrange)
    D, W, q = grid.matrices
    defects = ca.DM(D.toarray()) @ X.T - T * (ca.DM(W.toarray()) @ ca.horzcat(*F).T)
    params = ca.vertcat(x0, ca.vec(U), ca.vec(Win), T, p)
    residual = ca.Function("defects", [z, params], [ca.vec(defects)])
    root = ca.rootfinder(
        "collocation_states",
        "newton",
        residual,
        {"abstol": NEWTON_TOLERANCE, "abstolStep": 1e-16, "max_iter": 50, "error_on_fail": False},
    )
    end_u = tr.end_controls(U)
    ends = ocp.end_values((rows(X, 0, n_x), rows(X, nodes - 1, n_x)), end_u, tr.t0 + T, others)
    mayer = ocp.end_terms(ends, algebra).mayer
    value = ocp.sign * (mayer + T * (ca.DM(q).T @ ca.vertcat(*L)))
    payoff = ca.Function("payoff", [x0, z, U, Win, T, p], [value])
    return PointFunctions(residual, root, payoff)


def _horizon(tr: Transcription, params: Mapping[str, float]) -> float:
    return float(tr.bounds(params).t_lower)


def _params(tr: Transcription, params: Mapping[str, float]) -> np.ndarray:
    return np.array([params[n] for n in [*tr.ocp.parameters, *tr.ocp.design]], dtype=float)


def _data(
    tr: Transcription, params: Mapping[str, float], x0: np.ndarray, U: np.ndarray, Win: np.ndarray
) -> np.ndarray:
    T = _horizon(tr, params)
    parts = [x0, U.ravel(order="F"), Win.ravel(order="F"), [T], _params(tr, params)]
    return np.concatenate([np.asarray(v, dtype=float).ravel() for v in parts])


def states_at(
    tr: Transcription, params: Mapping[str, float], U: np.ndarray, Win: np.ndarray, start: np.ndarray
) -> np.ndarray | None:
    """The states (n_x × nodes) that satisfy the collocation equations for controls ``U`` and grid
    inputs ``Win`` from the initial node of ``start`` (whose other nodes start Newton's method);
    None when they are not met to ``DEFECT_TOLERANCE``."""
    functions = point_functions(tr)
    x0 = np.asarray(start[:, 0], dtype=float)
    data = _data(tr, params, x0, np.asarray(U, dtype=float), np.asarray(Win, dtype=float))
    guess = np.asarray(start[:, 1:], dtype=float).ravel()
    with np.errstate(all="ignore"):
        z = np.asarray(functions.root(guess, data), dtype=float).ravel()
        X = np.column_stack([x0, z.reshape(tr.n_x, -1)])
        scale = np.maximum(1.0, np.abs(X).max(axis=1, initial=0.0))
        gap = np.abs(np.asarray(functions.defects(z, data), dtype=float)).reshape(tr.n_x, -1) / scale[:, None]
    return X if np.isfinite(gap).all() and gap.max(initial=0.0) <= DEFECT_TOLERANCE else None


def payoff_at(
    tr: Transcription, params: Mapping[str, float], X: np.ndarray, U: np.ndarray, Win: np.ndarray
) -> float:
    """The player's payoff in its own sense (``sign`` undone) on the transcribed trajectory."""
    X = np.asarray(X, dtype=float)
    z = X[:, 1:].ravel()
    value = point_functions(tr).payoff(
        X[:, 0],
        z,
        np.asarray(U, dtype=float),
        np.asarray(Win, dtype=float),
        _horizon(tr, params),
        _params(tr, params),
    )
    return float(value)
