"""The derivatives IPOPT needs of a :class:`~gamespec_casadi.nlp.CollocationNlp`, assembled from the
derivatives of its one point function instead of differentiating the whole NLP graph (issue 16).

With the point variables ``V = [v_1 ... v_k]`` linear in the decision variables w (``vec V = S w``,
S a scaled selection) and the NLP linear in the point outputs ``O = [o(v_1) ... o(v_k)]`` with
constant coefficients, ``g = g_0(w) + C vec O`` and ``f = f_0(w) + c^T vec O`` (g_0: the defects'
``X D^T``, a constant matrix times w, and the boundary rows; f_0: the Mayer term and the rate
penalty), the chain rule gives

    jac g       = jac g_0 + C blkdiag(do_i/dv_i) S,
    grad f      = grad f_0 + S^T vec((do_i/dv_i)^T c_i),
    hess Lagr.  = hess (sigma f_0 + lambda^T g_0) + S^T blkdiag(d^2 (mu_i^T o_i)/dv_i^2) S,
    mu          = C^T lambda + sigma c.

The per-point derivatives are small SX functions evaluated over the points in blocks (one mapped
call per block of inlined points); each sum is one constant sparse matrix, computed here once from
the sparsity patterns, times the stacked nonzeros of its parts. CasADi differentiates only the
end-point terms. Building costs a few dozen MX nodes and a few sparse matrices whatever the grid (no
AD of a graph that grows with N, which is what makes ``nlpsol`` slow on the flat SX graph); each
evaluation does the per-point work once (no colored directions through the map, which is what makes
CasADi's own derivatives of the MX graph slow to evaluate).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from gamespec_casadi.nlp import CollocationNlp
from gamespec_casadi.sparse import Coo


@dataclass(frozen=True)
class AssembledNlp:
    """The NLP for ``nlpsol`` and its derivative functions, in the ``grad_f``, ``jac_g`` and
    ``hess_lag`` signatures of CasADi's IPOPT interface."""

    nlp: dict[str, Any]
    derivatives: dict[str, Any]


@dataclass(frozen=True)
class _PointDerivatives:
    """The point function's outputs with their Jacobian ``[o, do/dv]``, its weighted objective rows
    ``c^T o_rows`` alone and with their gradient ``(do_rows/dv)^T c``, and the Hessian
    ``d^2 (mu^T o)/dv^2`` (an SX function computes all its outputs, so one function a use)."""

    jacobian: Any
    cost: Any
    cost_gradient: Any
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
        cost=ca.Function("point_cost", [v, ca.vertcat(data, weights)], [cost]),
        cost_gradient=ca.Function(
            "point_cost_grad", [v, ca.vertcat(data, weights)], [cost, ca.gradient(cost, v)]
        ),
        hessian=ca.Function("point_hess", [v, ca.vertcat(data, mu)], [hessian]),
    )
    return derivatives, objective_rows


BLOCK = 16
"""The most points one mapped call evaluates (see :func:`_over_points`)."""


def _over_points(fn: Any, k: int, reduce: list[int] | None = None) -> Any:
    """``fn`` on k points: a map over blocks of m points (m the largest divisor of k up to
    :data:`BLOCK`), each block ``fn`` inlined m times into one flat SX function. A mapped call costs
    about 0.1 µs (a small point function's whole work), inlining about 0.3 µs per instruction and
    point to build: blocks pay the call once per m points for a build of m copies. ``reduce`` lists
    the outputs summed over the points."""
    m = max(d for d in range(1, min(BLOCK, k) + 1) if k % d == 0)
    args = [ca.SX.sym(fn.name_in(i), fn.size1_in(i), m) for i in range(fn.n_in())]
    out = fn.map(f"{fn.name()}_block", "serial", m, [], reduce or [])(*args)
    block = ca.Function(f"{fn.name()}_{m}", args, list(out) if isinstance(out, tuple) else [out])
    return block.map(f"{fn.name()}_points", "serial", k // m, [], reduce or [])


@dataclass(frozen=True)
class _Part:
    """One contribution to a sparse matrix: entry n adds ``weights[n] * vector[source[n]]`` at
    ``(rows[n], cols[n])``."""

    rows: np.ndarray
    cols: np.ndarray
    source: np.ndarray
    weights: np.ndarray
    vector: Any

    @classmethod
    def constant(cls, matrix: Coo) -> _Part:
        zeros = np.zeros(matrix.rows.size, dtype=np.int64)
        return cls(matrix.rows, matrix.cols, zeros, matrix.values, ca.DM.ones(1))

    @classmethod
    def symbolic(cls, matrix: Any, row_offset: int = 0) -> _Part:
        """The nonzeros of an MX matrix (its rows shifted by ``row_offset``)."""
        rows, cols = (np.array(v, dtype=int) for v in matrix.sparsity().get_triplet())
        nz = ca.sparsity_cast(matrix, ca.Sparsity.dense(matrix.nnz(), 1))
        return cls(rows + row_offset, cols, np.arange(matrix.nnz()), np.ones(matrix.nnz()), nz)


def _assemble(shape: tuple[int, int], parts: list[_Part]) -> Any:
    """The sum of the parts as one sparse MX matrix: one constant sparse matrix times the parts'
    vectors stacked gives the nonzeros of the sum (column-major, as CasADi stores them)."""
    keys = np.concatenate([part.cols.astype(np.int64) * shape[0] + part.rows for part in parts])
    ordered = np.sort(keys)
    unique = ordered[np.diff(ordered, prepend=-1) != 0]
    pattern = ca.Sparsity.triplet(*shape, (unique % shape[0]).tolist(), (unique // shape[0]).tolist())
    offsets = np.cumsum([0] + [part.vector.numel() for part in parts])
    source = np.concatenate([part.source + offset for part, offset in zip(parts, offsets, strict=False)])
    weights = np.concatenate([part.weights for part in parts])
    gather = Coo.of(np.searchsorted(unique, keys), source, weights, (unique.size, int(offsets[-1]))).dm()
    return ca.sparsity_cast(gather @ ca.vertcat(*(part.vector for part in parts)), pattern)


def _point_part(mapped: Any, block: Any, k: int, left: Coo | None, S: Coo) -> _Part:
    """The part ``L blkdiag(B_1, ..., B_k) S`` of a sum: the blocks the k side by side outputs of a
    mapped function (``block``: the sparsity of one), L the constraint weights C (a Jacobian) or
    ``S^T`` when ``left`` is None (a Hessian); S has one nonzero a row (a scaled selection)."""
    rows_b, cols_b = (np.array(v, dtype=int) for v in block.get_triplet())
    n_v = block.size2()
    point = np.repeat(np.arange(k), rows_b.size)
    column = point * n_v + np.tile(cols_b, k)
    order = np.argsort(S.rows, kind="stable")
    assert np.array_equal(S.rows[order], np.arange(S.shape[0])), "each point variable is one variable"
    var, scale = S.cols[order], S.values[order]
    cols = var[column]
    row = point * block.size1() + np.tile(rows_b, k)
    nz = ca.sparsity_cast(mapped, ca.Sparsity.dense(mapped.nnz(), 1))
    if left is None:
        return _Part(var[row], cols, np.arange(row.size), scale[row] * scale[column], nz)
    colind, left_rows, left_values = left.compressed_columns()
    counts = np.diff(colind)[row]
    entry = np.repeat(np.arange(row.size), counts)
    offsets = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    at = np.repeat(colind[row], counts) + offsets
    return _Part(left_rows[at], cols[entry], entry, left_values[at] * scale[column][entry], nz)


def assembled_nlp(nlp: CollocationNlp) -> AssembledNlp:
    """The NLP (MX) with its derivative functions assembled from the point function's."""
    w, p = nlp.w, nlp.p
    n_o, k = nlp.outputs.shape
    S, C = nlp.selection_dm, nlp.weights_dm
    c = nlp.cost_weights.reshape((n_o, k), order="F")
    point, objective_rows = _point_derivatives(nlp.point, c)
    V, data = nlp.points, nlp.point_data

    cost, cost_again, cost_grad = nlp.cost, nlp.cost, ca.gradient(nlp.cost, w)
    if objective_rows:
        weighted = ca.vertcat(data, ca.DM(c[objective_rows, :]))
        cost += _over_points(point.cost, k, [0])(V, weighted)
        total, grads = _over_points(point.cost_gradient, k, [0])(V, weighted)
        cost_again, cost_grad = cost_again + total, cost_grad + S.T @ ca.vec(grads)
    g = nlp.constraints(_over_points(nlp.point, k)(V, data))

    shape_j = (C.size1(), w.numel())
    values, point_jac = _over_points(point.jacobian, k)(V, data)
    parts = [_Part.constant(nlp.linear)]
    parts.append(_point_part(point_jac, point.jacobian.sparsity_out(1), k, nlp.weights, nlp.selection))
    boundary = nlp.boundary
    if nlp.boundary_rows:
        parts.append(_Part.symbolic(ca.jacobian(boundary, w), nlp.boundary_rows[0]))
    jac_g = _assemble(shape_j, parts)

    sigma, lam = ca.MX.sym("lam_f"), ca.MX.sym("lam_g", C.size1())
    mu = ca.reshape(C.T @ lam, n_o, k) + sigma * ca.DM(c)
    point_hess = _over_points(point.hessian, k)(V, ca.vertcat(data, mu))
    hess0 = ca.triu(ca.hessian(sigma * nlp.cost + ca.dot(lam[nlp.boundary_rows], boundary), w)[0])
    parts = [_point_part(point_hess, point.hessian.sparsity_out(0), k, None, nlp.selection)]
    hess_l = _assemble((w.numel(), w.numel()), [*parts, _Part.symbolic(hess0)])
    return AssembledNlp(
        nlp={"x": w, "p": p, "f": cost, "g": g},
        derivatives={
            "grad_f": ca.Function("nlp_grad_f", [w, p], [cost_again, cost_grad]),
            "jac_g": ca.Function("nlp_jac_g", [w, p], [nlp.constraints(values), jac_g]),
            "hess_lag": ca.Function("nlp_hess_l", [w, p, sigma, lam], [hess_l]),
        },
    )
