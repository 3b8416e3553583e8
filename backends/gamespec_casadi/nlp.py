"""A :class:`~gamespec.ocp.transcription.Transcription` as CasADi expressions: the decision variables,
the NLP parameters, and the objective and constraints as functions of the variables and of the
outputs of one *point function* evaluated at every evaluation point.

Decision variables ``w = [vec(X / s_x); vec(U / s_u); d; T]`` (s: the scale factors, d: the design
variables), NLP parameters ``p = [params; vec(Win); T]`` (the grid inputs, one block of n_w × n_eval
values, and a fixed horizon). At evaluation point i the point function maps its variables
``v_i = [x_i; u_i; d]`` (and T when free; linear in w) and its data (inputs, normalized time,
parameters) to

    o_i = [T f_i; T L_i; path_i; T integrand_i],

and the NLP is linear in the outputs ``O = [o_1 ... o_k]`` (constant coefficients):

    g = [vec((X D^T - O_f W^T) / s_x); vec(O_path^T); boundary(ends, interior); O_integrand q],
    J = mayer(ends) + O_L q + rate penalty(U) + misfit(interior),

the defects ``D X - T W F`` and the Lagrange quadrature of :mod:`gamespec.ocp.collocation` (the
interior points' constraints and least-squares misfit, :mod:`gamespec.ocp.events`, linear
combinations of X, are end-point terms here), with the
constant matrices built here once. That split is what :mod:`gamespec_casadi.assembly`
differentiates; :meth:`CollocationNlp.closed` puts the mapped point function in place of ``O`` for
the flat SX graph and the MX graph.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import casadi as ca
import numpy as np

from gamespec.ocp.transcription import Transcription
from gamespec.symbolic.grammar import Relation
from gamespec.symbolic.library import Library, LibraryAlgebra
from gamespec_casadi.sparse import Coo


@dataclass(frozen=True)
class CollocationNlp:
    """The collocation NLP with the point outputs as a free symbol ``outputs`` (n_o × k):
    ``vec(points) = selection w``, ``g = linear w + weights vec(outputs) + boundary rows`` and
    ``f = cost + cost_weights^T vec(outputs)`` (constant sparse matrices and a NumPy vector;
    ``boundary`` and ``cost`` hold the end-point terms and the rate penalty)."""

    w: Any
    p: Any
    point: Any
    point_data: Any
    outputs: Any
    selection: Coo
    linear: Coo
    weights: Coo
    cost_weights: np.ndarray
    boundary: Any
    boundary_rows: list[int]
    cost: Any
    lbg: np.ndarray
    ubg: np.ndarray
    n_defects: int

    @cached_property
    def selection_dm(self) -> Any:
        return self.selection.dm()

    @cached_property
    def weights_dm(self) -> Any:
        return self.weights.dm()

    @cached_property
    def linear_dm(self) -> Any:
        return self.linear.dm()

    @property
    def points(self) -> Any:
        """The point variables ``[v_1 ... v_k]`` (n_v × k)."""
        return ca.reshape(self.selection_dm @ self.w, -1, self.outputs.size2())

    def objective(self, outputs: Any) -> Any:
        return self.cost + ca.DM(self.cost_weights).T @ ca.vec(outputs)

    def constraints(self, outputs: Any) -> Any:
        """``g`` for given point outputs (the symbol, or the mapped point function)."""
        return self.rest_constraints() + self.weights_dm @ ca.vec(outputs)

    def rest_constraints(self) -> Any:
        """``g`` at zero point outputs: the defects' ``X D^T`` and the boundary rows."""
        rows = self.boundary_embedding()
        return self.linear_dm @ self.w + (rows @ self.boundary if self.boundary_rows else 0)

    def boundary_embedding(self) -> Any:
        """The columns of the identity that put the boundary rows in place in g."""
        return ca.DM.eye(self.linear.shape[0])[:, self.boundary_rows]

    def mapped_outputs(self) -> Any:
        """The point function mapped over the points."""
        return self.point.map(self.outputs.size2())(self.points, self.point_data)

    def closed(self) -> dict[str, Any]:
        """The NLP (``x, p, f, g``) with the mapped point function in place of ``outputs``."""
        values = self.mapped_outputs()
        return {"x": self.w, "p": self.p, "f": self.objective(values), "g": self.constraints(values)}


def point_function(tr: Transcription, lib: Library) -> Any:
    """The SX function ``o(v, data)`` of one evaluation point: variables ``v = [x; u; d]`` (and the
    horizon ``T`` when it is free), ``data = [w; tau; p]`` (grid inputs, normalized time with
    ``t = t0 + T tau``, parameters; and a fixed horizon ``T``), to ``[T f; T L; path; T integrand]``
    (the terms of the defects and quadratures of :mod:`gamespec.ocp.collocation`). Two arguments,
    since a mapped call costs per argument and point."""
    ocp = tr.ocp
    x, u, d = ca.SX.sym("x", tr.n_x), ca.SX.sym("u", tr.n_u), ca.SX.sym("d", tr.n_d)
    horizon, tau = ca.SX.sym("T"), ca.SX.sym("tau")
    w, p = ca.SX.sym("w", tr.n_w), ca.SX.sym("p", len(ocp.parameters))
    others = dict(zip(ocp.parameters + ocp.design, ca.vertsplit(ca.vertcat(p, d)), strict=True))
    split = (ca.vertsplit(v) for v in (x, u, w))
    values = ocp.running_values(*split, tr.t0 + horizon * tau, others)
    terms = ocp.running_terms(values, LibraryAlgebra(lib))
    f, path = ca.vertcat(*terms.dynamics), ca.vertcat(*(r.expr for r in terms.path))
    o = ca.vertcat(horizon * f, horizon * terms.lagrange, path, horizon * ca.vertcat(*terms.integrands))
    if tr.free_time:
        return ca.Function("point", [ca.vertcat(x, u, d, horizon), ca.vertcat(w, tau, p)], [o])
    return ca.Function("point", [ca.vertcat(x, u, d), ca.vertcat(w, tau, p, horizon)], [o])


def _point_selection(tr: Transcription, sx: np.ndarray, su: np.ndarray, n_var: int) -> Coo:
    """S with ``vec([v_1 ... v_k]) = S w``: point i's ``x`` is state node ``eval_index[i]`` times the
    state scales, its ``u`` the i-th control column times the control scales, then d (and T)."""
    nx, nu, nd, n = tr.n_x, tr.n_u, tr.n_d, tr.grid.n_nodes
    e = tr.grid.eval_index
    k = len(e)
    n_v = nx + nu + nd + int(tr.free_time)
    point = np.arange(k)[:, None]
    rows, cols, vals = [], [], []
    for offset, width, col, val in (
        (0, nx, e[:, None] * nx + np.arange(nx), np.broadcast_to(sx, (k, nx))),
        (nx, nu, nx * n + point * nu + np.arange(nu), np.broadcast_to(su, (k, nu))),
        (nx + nu, nd, nx * n + nu * k + np.broadcast_to(np.arange(nd), (k, nd)), np.ones((k, nd))),
        (n_v - 1, int(tr.free_time), np.full((k, int(tr.free_time)), n_var - 1), np.ones((k, 1))),
    ):
        if width:
            rows.append((point * n_v + offset + np.arange(width)).ravel())
            cols.append(np.broadcast_to(col, (k, width)).ravel())
            vals.append(np.broadcast_to(val, (k, width)).ravel())
    return Coo.of(np.concatenate(rows), np.concatenate(cols), np.concatenate(vals), (n_v * k, n_var))


def _output_weights(tr: Transcription, n_o: int, n_boundary: int, sx: np.ndarray) -> tuple[Coo, np.ndarray]:
    """C and c with ``g = ... + C vec(O)`` (the defects' ``- vec(O_f W^T)``, each state's rows
    divided by its scale ``sx``, the path rows
    ``vec(O_path^T)``, the integrals ``O_integrand q``) and ``f = ... + c^T vec(O)`` (``O_L q``)."""
    structure = tr.ocp.running_structure
    nx, n_path, n_int = tr.n_x, len(structure.path), len(structure.integrands)
    _, W, q = tr.grid.triplets
    k = len(q)
    rows, cols, values, shape = W
    unscale = Coo.of(np.arange(nx), np.arange(nx), 1.0 / sx, (nx, n_o))
    defects = Coo.of(rows, cols, -values, shape).kron(unscale)
    r, i = np.meshgrid(np.arange(n_path), np.arange(k), indexing="ij")
    path = Coo.of(i + k * r, nx + 1 + r + n_o * i, 1.0, (k * n_path, k * n_o))
    boundary = Coo.of([], [], [], (n_boundary, k * n_o))
    quadrature = Coo.of(np.zeros(k), np.arange(k), q, (1, k))
    integrals = quadrature.kron(Coo.eye(n_int, n_o, nx + 1 + n_path))
    cost = np.kron(q, np.eye(n_o)[nx])
    return Coo.vstack([defects, path, boundary, integrals]), cost


def collocation_nlp(
    tr: Transcription, lib: Library, outer: Any, sx: np.ndarray, su: np.ndarray
) -> CollocationNlp:
    """The NLP of ``tr`` on symbols of type ``outer`` (``ca.SX`` or ``ca.MX``), the variables scaled
    by ``sx`` (states) and ``su`` (controls)."""
    ocp, grid = tr.ocp, tr.grid
    nx, nu, nw, npar, k = tr.n_x, tr.n_u, tr.n_w, len(ocp.parameters), len(grid.eval_index)
    running = ocp.running_structure
    X_scaled, U_scaled = outer.sym("X", nx, grid.n_nodes), outer.sym("U", nu, k)
    U = ca.diag(ca.DM(su)) @ U_scaled
    T = outer.sym("T") if tr.free_time else None
    design = outer.sym("d", tr.n_d)
    p_all = outer.sym("p_all", npar + nw * k + (0 if tr.free_time else 1))
    params = p_all[:npar, :]
    Win = ca.reshape(p_all[npar : npar + nw * k], nw, k)
    horizon = T if tr.free_time else p_all[npar + nw * k]
    w = ca.vertcat(ca.vec(X_scaled), ca.vec(U_scaled), design, *([T] if tr.free_time else []))
    n_o = nx + 1 + len(running.path) + len(running.integrands)

    x_ends = ca.DM(sx) * X_scaled[:, [0, grid.n_nodes - 1]]
    others = dict(zip(ocp.parameters + ocp.design, ca.vertsplit(ca.vertcat(params, design)), strict=True))
    x_first_last = (ca.vertsplit(x_ends[:, 0]), ca.vertsplit(x_ends[:, 1]))
    ends = ocp.end_values(x_first_last, tr.end_controls(U), tr.t0 + horizon, others)
    end_terms = ocp.end_terms(ends, LibraryAlgebra(lib))
    interior = tr.interior.terms(ca.diag(ca.DM(sx)) @ X_scaled, others, LibraryAlgebra(lib))
    rows = [*end_terms.boundary, *interior.constraints]
    boundary = ca.vertcat(*(r.expr for r in rows))
    cost = end_terms.mayer + tr.rate_penalty(U) + interior.misfit

    D = Coo.of(*grid.triplets[0])
    n_defects = D.shape[0] * nx
    weights, cost_weights = _output_weights(tr, n_o, len(rows), sx)
    # the defects D X - T W F of state i divided by its scale: D (X / s_x) - T W F / s_x
    linear = D.kron(Coo.eye(nx, nx)).resized((weights.shape[0], w.numel()))
    lower, upper = [np.zeros(n_defects)], [np.zeros(n_defects)]
    for r in running.path:
        lower.append(np.full(k, r.lower))
        upper.append(np.full(k, r.upper))
    integrals = ocp.integral_bounds(ocp.parameter_values())
    for group in (rows, [Relation(None, lo, hi) for lo, hi in integrals]):
        lower.append(np.array([r.lower for r in group]))
        upper.append(np.array([r.upper for r in group]))
    first_boundary = n_defects + k * len(running.path)
    return CollocationNlp(
        w=w,
        p=p_all,
        point=point_function(tr, lib),
        point_data=ca.vertcat(
            Win,
            ca.DM(grid.eval_tau).T,
            ca.repmat(params, 1, k),
            *([] if tr.free_time else [ca.repmat(horizon, 1, k)]),
        ),
        outputs=outer.sym("o", n_o, k),
        selection=_point_selection(tr, sx, su, w.numel()),
        linear=linear,
        weights=weights,
        cost_weights=cost_weights,
        boundary=boundary,
        boundary_rows=list(range(first_boundary, first_boundary + len(rows))),
        cost=cost,
        lbg=np.concatenate(lower),
        ubg=np.concatenate(upper),
        n_defects=n_defects,
    )
