"""The derivatives IPOPT needs of a :class:`~gamespec_casadi.nlp.CollocationNlp`, assembled from the
derivatives of its one point function instead of differentiating the whole NLP graph (issue 16).

With the point variables ``V = [v_1 ... v_k]`` linear in the decision variables w (``vec V = S w``,
S constant) and the NLP linear in the point outputs ``O = [o(v_1) ... o(v_k)]`` with constant
coefficients, ``g = g_0(w) + C vec O`` and ``f = f_0(w) + c^T vec O`` (g_0, f_0: the NLP at O = 0,
i.e. the defects' ``X D^T``, the end-point terms, the rate penalty), the chain rule gives

    jac g       = jac g_0 + C blkdiag(do_i/dv_i) S,
    grad f      = grad f_0 + S^T vec((do_i/dv_i)^T c_i),
    hess Lagr.  = hess (sigma f_0 + lambda^T g_0) + S^T blkdiag(d^2 (mu_i^T o_i)/dv_i^2) S,
    mu          = C^T lambda + sigma c,

with the per-point derivatives (small SX functions) mapped over the points and the sums sparse
products with constant matrices. The rows of g_0 affine in (w, p) have a constant Jacobian, taken
once; CasADi differentiates only the rest (the end-point terms). Building costs a few dozen CasADi
nodes whatever the grid, and each evaluation does the per-point work once.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from gamespec_casadi.nlp import CollocationNlp


@dataclass(frozen=True)
class AssembledNlp:
    """The NLP for ``nlpsol`` and its derivative functions, in the ``grad_f``, ``jac_g`` and
    ``hess_lag`` signatures of CasADi's IPOPT interface."""

    nlp: dict[str, Any]
    derivatives: dict[str, Any]


@dataclass(frozen=True)
class _PointDerivatives:
    """The point function's outputs with their Jacobian ``[o, do/dv]``, its weighted objective rows
    with their gradient ``[c^T o_rows, (do_rows/dv)^T c]`` and the Hessian ``d^2 (mu^T o)/dv^2``."""

    jacobian: Any
    objective: Any
    hessian: Any


def _point_derivatives(point: Any, c: np.ndarray) -> tuple[_PointDerivatives, list[int]]:
    """The derivatives and the rows of o the objective weighs (``c``, n_o × k, nonzero where the
    output is not identically zero)."""
    v, data = point.sx_in()
    o = point(v, data)
    weighed = np.any(c != 0, axis=1)
    objective_rows = [i for i in range(o.numel()) if weighed[i] and not o[i].is_zero()]
    weights = ca.SX.sym("c", len(objective_rows))
    cost = ca.dot(weights, o[objective_rows])
    mu = ca.SX.sym("mu", o.numel())
    hessian = ca.triu(ca.hessian(ca.dot(mu, o), v)[0])
    derivatives = _PointDerivatives(
        jacobian=ca.Function("point_jac", [v, data], [o, ca.jacobian(o, v)]),
        objective=ca.Function("point_cost", [v, ca.vertcat(data, weights)], [cost, ca.gradient(cost, v)]),
        hessian=ca.Function("point_hess", [v, ca.vertcat(data, mu)], [hessian]),
    )
    return derivatives, objective_rows


def _over_points(fn: Any, k: int, reduce: list[int] | None = None) -> Any:
    """``fn`` on k points at once, inlined into one flat SX function: no per-point call overhead (about
    0.1 µs a point and call, which dominates a function as small as a running cost) for a build in
    proportion to k times its size (so only for the cost; the Jacobian and the Hessian are mapped).
    ``reduce`` lists the outputs summed over the points."""
    args = [ca.SX.sym(fn.name_in(i), fn.size1_in(i), k) for i in range(fn.n_in())]
    mapped = fn.map(f"{fn.name()}_points", "serial", k, [], reduce or [])
    out = mapped(*args)
    return ca.Function(f"{fn.name()}_{k}", args, list(out) if isinstance(out, tuple) else [out])


def _block_diagonal(mapped: Any, block: Any, k: int) -> Any:
    """The k blocks side by side of a mapped output (``[B_1 ... B_k]``, each with sparsity ``block``)
    as ``blkdiag(B_1, ..., B_k)``: the same nonzeros in the same order, so a cast, no copy."""
    return ca.sparsity_cast(mapped, ca.diagcat(*[block] * k))


def assembled_nlp(nlp: CollocationNlp) -> AssembledNlp:
    """The NLP (MX) with its derivative functions assembled from the point function's."""
    w, p = nlp.w, nlp.p
    n_o, k = nlp.outputs.shape
    S, C = nlp.selection, nlp.weights
    c = ca.reshape(nlp.cost_weights, n_o, k)
    point, objective_rows = _point_derivatives(nlp.point, np.array(c))
    V, data = nlp.points, nlp.point_data

    cost, cost_grad = nlp.cost, ca.gradient(nlp.cost, w)
    if objective_rows:
        total, grads = _over_points(point.objective, k, [0])(V, ca.vertcat(data, c[objective_rows, :]))
        cost, cost_grad = cost + total, cost_grad + S.T @ ca.vec(grads)
    g = nlp.constraints(nlp.mapped_outputs())

    rows, boundary = nlp.boundary_embedding(), nlp.boundary
    jac0 = nlp.linear + (rows @ ca.jacobian(boundary, w) if nlp.boundary_rows else 0)
    values, point_jac = point.jacobian.map(k)(V, data)
    point_jac = _block_diagonal(point_jac, point.jacobian.sparsity_out(1), k)
    jac_g = jac0 + C @ (point_jac @ S)

    sigma, lam = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", C.size1())
    mu = ca.reshape(C.T @ lam, n_o, k) + sigma * c
    point_hess = point.hessian.map(k)(V, ca.vertcat(data, mu))
    point_hess = _block_diagonal(point_hess, point.hessian.sparsity_out(0), k)
    hess0 = ca.hessian(sigma * nlp.cost + ca.dot(lam[nlp.boundary_rows], boundary), w)[0]
    hess_l = ca.triu(hess0) + S.T @ (point_hess @ S)
    return AssembledNlp(
        nlp={"x": w, "p": p, "f": cost, "g": g},
        derivatives={
            "grad_f": ca.Function("nlp_grad_f", [w, p], [cost, cost_grad]),
            "jac_g": ca.Function("nlp_jac_g", [w, p], [nlp.constraints(values), jac_g]),
            "hess_lag": ca.Function("nlp_hess_l", [w, p, sigma, lam], [hess_l]),
        },
    )
