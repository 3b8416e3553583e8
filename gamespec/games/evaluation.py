"""A player's payoff at a given joint strategy, under the transcription its best response is solved on.

A best response's Result is a trajectory at ``(BR_p, s_{-p})``; a Nash gap also needs each player's
payoff at the returned point ``s`` itself, where no solver ran. Here the states of ``s`` are those
of the collocation equations of the player's own model (``D X − T W F(X, U, W, t) = 0`` with the
initial node fixed, :mod:`gamespec.ocp.collocation`), solved by SciPy with the controls and the
grid inputs held, and the payoff is the transcription's own objective ``Φ(ends) + T qᵀL`` (eq. 7.1
as the NLP states it, without the control-rate penalty, as the Result's objective), so that
``J_p(s) − J_p(BR_p, s_{-p})`` compares two numbers of the same discrete problem.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from scipy.optimize import root

from gamespec.ocp.checks import ARRAYS
from gamespec.ocp.transcription import Transcription

DEFECT_TOLERANCE = 1e-10
"""Largest collocation defect, relative to ``max(1, max |x|)``, accepted for the states of a point."""


def _params(tr: Transcription, params: Mapping[str, float]) -> list[np.float64]:
    return [np.float64(params[n]) for n in [*tr.ocp.parameters, *tr.ocp.design]]


def _running(
    tr: Transcription, X: np.ndarray, U: np.ndarray, Win: np.ndarray, T: float, params
) -> np.ndarray:
    """The dynamics (first rows) and the Lagrange integrand (last row, minimization form) at the
    evaluation points."""
    t = tr.t0 + T * tr.grid.eval_tau
    return tr.ocp.running_function(*X[:, tr.grid.eval_index], *U, *Win, *_params(tr, params), t)


def states_at(
    tr: Transcription, params: Mapping[str, float], U: np.ndarray, Win: np.ndarray, start: np.ndarray
) -> np.ndarray | None:
    """The states (n_x × nodes) that satisfy the collocation equations for controls ``U`` and grid
    inputs ``Win`` from the initial node of ``start`` (whose other nodes start the solve); None when
    SciPy does not meet them to ``DEFECT_TOLERANCE``."""
    D, W, _ = tr.grid.matrices
    T = float(tr.bounds(params).t_lower)
    n_x = tr.n_x
    x0 = np.asarray(start[:, 0], dtype=float)

    def states(z: np.ndarray) -> np.ndarray:
        return np.column_stack([x0, z.reshape(n_x, -1)])

    def defects(z: np.ndarray) -> np.ndarray:
        X = states(z)
        F = np.broadcast_to(_running(tr, X, U, Win, T, params)[:-1], (n_x, W.shape[1]))
        return (D @ X.T - T * (W @ F.T)).T.ravel()

    with np.errstate(all="ignore"):
        solution = root(defects, np.asarray(start[:, 1:], dtype=float).ravel(), method="hybr", tol=1e-14)
        X = states(solution.x)
        scale = np.maximum(1.0, np.abs(X).max(axis=1, initial=0.0))
        gap = np.abs(defects(solution.x)).reshape(n_x, -1) / scale[:, None]
    return X if np.isfinite(gap).all() and gap.max(initial=0.0) <= DEFECT_TOLERANCE else None


def payoff_at(
    tr: Transcription, params: Mapping[str, float], X: np.ndarray, U: np.ndarray, Win: np.ndarray
) -> float:
    """The player's payoff in its own sense (``sign`` undone) on the transcribed trajectory."""
    T = float(tr.bounds(params).t_lower)
    arrays = {n: np.float64(v) for n, v in params.items()}
    lagrange = np.broadcast_to(_running(tr, X, U, Win, T, params)[-1], tr.grid.eval_tau.shape)
    ends = tr.ocp.end_values((X[:, 0], X[:, -1]), tr.end_controls(U), np.float64(tr.t0 + T), arrays)
    mayer = float(tr.ocp.end_terms(ends, ARRAYS).mayer)
    q = tr.grid.triplets[2]
    return tr.ocp.sign * (mayer + T * float(q @ lagrange))
