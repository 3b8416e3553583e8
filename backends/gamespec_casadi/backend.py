"""The ``casadi`` backend: an ``optimal_control`` spec as a CasADi NLP by direct collocation.

The NLP is built once (on one flat SX graph, or with ``graph: mx`` an MX graph around the mapped
per-point function) from the backend-neutral :class:`~gamespec.ocp.transcription.Transcription`:
decision variables ``[vec(X / s_x); vec(U / s_u); d; T]`` (s: the scale factors, d: the design
variables), defects ``D X - T W F``
with ``F`` a mapped CasADi function over the evaluation points, and the problem's parameters, the
grid inputs (one block of n_w × n_eval values) and a fixed horizon as NLP parameters ``p = [params;
vec(Win); T]``, so a re-solve with new values reuses the solver and warm-starts from the last
solution.
"""

from __future__ import annotations

import time
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import Field, ValidationInfo, field_validator

from gamespec.backend import Availability, Inputs
from gamespec.backend.collocation import IPOPT_DEFAULTS, CollocationBackend, CollocationModel
from gamespec.errors import BackendError
from gamespec.ocp.collocation import Triplets
from gamespec.ocp.transcription import Guess, Transcription
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.symbolic.translate import Library, translate

STATUS_MAP = {
    "Solve_Succeeded": Status.OPTIMAL,
    "Solved_To_Acceptable_Level": Status.FEASIBLE,
    "Feasible_Point_Found": Status.FEASIBLE,
    "Infeasible_Problem_Detected": Status.LOCALLY_INFEASIBLE,
    "Diverging_Iterates": Status.UNBOUNDED,
    "Maximum_Iterations_Exceeded": Status.ITERATION_LIMIT,
    "Maximum_CpuTime_Exceeded": Status.TIME_LIMIT,
    "Maximum_WallTime_Exceeded": Status.TIME_LIMIT,
    "Restoration_Failed": Status.NUMERICAL_ERROR,
    "Error_In_Step_Computation": Status.NUMERICAL_ERROR,
    "Invalid_Number_Detected": Status.NUMERICAL_ERROR,
}
"""IPOPT's return status → gamespec's Status. IPOPT is a local solver: ``Infeasible_Problem_Detected``
means it converged to a point of local infeasibility, hence ``locally_infeasible``."""


class CasadiOptions(StrictModel):
    """Options block ``solver.options.casadi``: IPOPT options passed through, and a tolerance."""

    solver: str = Field("ipopt", description="NLP solver plugin of CasADi's nlpsol.")
    tol: float = Field(1e-8, gt=0, description="IPOPT's tol.")
    max_iter: int = Field(3000, ge=1)
    max_wall_time: float = Field(300.0, gt=0, description="IPOPT's wall-time limit in seconds.")
    ipopt: dict[str, Any] = Field(default_factory=dict, description="Further IPOPT options.")
    warm_start: bool = Field(True, description="Re-solves start from the previous solution.")
    graph: Literal["sx", "mx"] = Field(
        "sx",
        description="Outer NLP graph: 'sx' flattens every interval into one SX graph (slow nlpsol build"
        " at large N, fastest IPOPT iterations and re-solves); 'mx' keeps the per-point function as one"
        " mapped node (a 3-8x faster build at N = 1000, 1.2-2x slower iterations): for one-shot solves"
        " of large grids.",
    )

    @field_validator("ipopt")
    @classmethod
    def _known_to_ipopt(cls, ipopt: dict[str, Any], info: ValidationInfo) -> dict[str, Any]:
        """``ipopt`` holds options IPOPT itself knows and accepts (checked against its own list)."""
        if ipopt and info.data.get("solver") == "ipopt":
            from gamespec_casadi.ipopt_options import check_ipopt_options

            check_ipopt_options(ipopt)
        return ipopt


def casadi_library(ca: Any) -> Library:
    """CasADi's functions by gamespec's names; ``heaviside(x) = (1 + sign(x))/2``, which is 1/2 at 0
    as SymPy's ``Heaviside`` (CasADi's ``sign(0) = 0``)."""
    return Library.from_namespace(
        ca, abs=ca.fabs, min=ca.fmin, max=ca.fmax, heaviside=lambda x: 0.5 * (1 + ca.sign(x))
    )


def transposed(ca: Any, triplets: Triplets) -> Any:
    """The transpose of a sparse matrix given as :attr:`~gamespec.ocp.collocation.Grid.triplets`,
    as a sparse ``casadi.DM`` (built without SciPy)."""
    rows, cols, values, (n_rows, n_cols) = triplets
    return ca.DM.triplet(cols.tolist(), rows.tolist(), ca.DM(values), n_cols, n_rows)


class CasadiModel(CollocationModel):
    """The NLP and its solver, built once."""

    def __init__(self, spec: OptimalControlSpec, options: CasadiOptions) -> None:
        import casadi as ca

        if not ca.has_nlpsol(options.solver):
            raise BackendError(f"casadi has no NLP solver plugin {options.solver!r}")
        self.ca = ca
        self.tr = tr = Transcription(spec)
        self.options = options
        ocp, grid = tr.ocp, tr.grid
        lib = casadi_library(ca)
        nx, nu, nw, npar = tr.n_x, tr.n_u, tr.n_w, len(ocp.p)
        x, u, w = ca.SX.sym("x", nx), ca.SX.sym("u", nu), ca.SX.sym("w", nw)
        p, t = ca.SX.sym("p", npar + tr.n_d), ca.SX.sym("t")
        values = {ocp.t: t}
        for symbols, var in ((ocp.x, x), (ocp.u, u), (ocp.w, w), (ocp.p + ocp.d, p)):
            values |= dict(zip(symbols, ca.vertsplit(var), strict=True))
        f = ca.vertcat(*(translate(e, values, lib) for e in ocp.dynamics))
        L = translate(ocp.lagrange, values, lib)
        path = ca.vertcat(*(translate(r.expr, values, lib) for r in ocp.path))
        integrand = ca.vertcat(*(translate(r.expr, values, lib) for r in ocp.integrals))
        k = len(grid.eval_index)
        point = ca.Function("point", [x, u, w, t, p], [f, L, path, integrand]).map(k)

        outer = ca.MX if options.graph == "mx" else ca.SX
        self.sx, self.su = tr.scales(tr.ocp.parameter_values())
        X_scaled, U_scaled = outer.sym("X", nx, grid.n_nodes), outer.sym("U", nu, k)
        X = ca.diag(ca.DM(self.sx)) @ X_scaled
        U = ca.diag(ca.DM(self.su)) @ U_scaled
        T = outer.sym("T") if tr.free_time else None
        design = outer.sym("d", tr.n_d)
        p_all = outer.sym("p_all", npar + nw * k + (0 if tr.free_time else 1))
        params = ca.vertcat(p_all[:npar, :], design)
        Win = ca.reshape(p_all[npar : npar + nw * k], nw, k)
        horizon = T if tr.free_time else p_all[npar + nw * k]
        t_eval = tr.t0 + horizon * ca.DM(grid.eval_tau).T
        F, Lv, G, Iv = point(X[:, grid.eval_index.tolist()], U, Win, t_eval, params)
        D, W, q = grid.triplets
        defects = X @ transposed(ca, D) - horizon * (F @ transposed(ca, W))

        ends = dict(zip(ocp.x0, ca.vertsplit(X[:, 0]), strict=True))
        ends |= dict(zip(ocp.xf, ca.vertsplit(X[:, -1]), strict=True)) | {ocp.tf: tr.t0 + horizon}
        ends |= dict(zip(ocp.p + ocp.d, ca.vertsplit(params), strict=True))
        first, last = tr.end_controls(U)
        ends |= dict(zip(ocp.u0, first, strict=True)) | dict(zip(ocp.uf, last, strict=True))
        mayer = translate(ocp.mayer, ends, lib)
        boundary = [translate(r.expr, ends, lib) for r in ocp.boundary]
        objective = mayer + horizon * (Lv @ ca.DM(q)) + tr.rate_penalty(U)

        self.n_defects = defects.numel()
        integrals = horizon * (Iv @ ca.DM(q))
        g = ca.vertcat(ca.vec(defects), ca.vec(G.T), *boundary, integrals)
        w = ca.vertcat(ca.vec(X_scaled), ca.vec(U_scaled), design, *([T] if tr.free_time else []))
        lower = [np.zeros(self.n_defects)]
        upper = [np.zeros(self.n_defects)]
        for r in ocp.path:
            lower.append(np.full(k, r.lower))
            upper.append(np.full(k, r.upper))
        lower += [np.array([r.lower for r in ocp.boundary])]
        upper += [np.array([r.upper for r in ocp.boundary])]
        lower += [np.array([r.lower for r in ocp.integrals])]
        upper += [np.array([r.upper for r in ocp.integrals])]
        self.lbg, self.ubg = np.concatenate(lower), np.concatenate(upper)
        ipopt = {"print_level": 0, "sb": "yes", "tol": options.tol, "max_iter": options.max_iter}
        ipopt["max_wall_time"] = options.max_wall_time
        nlp_opts = {"ipopt": ipopt | IPOPT_DEFAULTS | options.ipopt, "print_time": False}
        self.solver = ca.nlpsol(
            "gamespec", options.solver, {"x": w, "p": p_all, "f": objective, "g": g}, nlp_opts
        )
        self.shape = (nx, grid.n_nodes, nu, k)
        self._last: np.ndarray | None = None

    def _pack(self, X: np.ndarray, U: np.ndarray, d: np.ndarray, T: float) -> np.ndarray:
        """The NLP's variables: X and U divided by their scale factors."""
        parts = [(X / self.sx[:, None]).ravel(order="F"), (U / self.su[:, None]).ravel(order="F"), d]
        return np.concatenate([*parts, [T]] if self.tr.free_time else parts)

    def _unpack(self, w: np.ndarray, params_T: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        nx, n, nu, k = self.shape
        X = w[: nx * n].reshape((nx, n), order="F") * self.sx[:, None]
        U = w[nx * n : nx * n + nu * k].reshape((nu, k), order="F") * self.su[:, None]
        d = w[nx * n + nu * k : nx * n + nu * k + self.tr.n_d]
        T = float(w[-1]) if self.tr.free_time else params_T
        return X, U, d, T

    def _constraint_bounds(self, params: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
        """``lbg, ubg`` with the integral constraints' bounds (the last rows of g) for ``params``."""
        n = len(self.tr.ocp.integrals)
        if not n:
            return self.lbg, self.ubg
        lbg, ubg = self.lbg.copy(), self.ubg.copy()
        lbg[-n:], ubg[-n:] = np.array(self.tr.ocp.integral_bounds(params)).T
        return lbg, ubg

    def solve_once(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        tr = self.tr
        params = tr.ocp.parameter_values(parameters)
        b = tr.bounds(params)
        Win = tr.input_values(params, inputs)
        if guess is None and self._last is not None and self.options.warm_start:
            w0 = self._last
        else:
            start: Guess = tr.guess(params, guess)
            w0 = self._pack(start.X, start.U, start.d, start.T)
        lbx = self._pack(b.x_lower, b.u_lower, b.d_lower, b.t_lower)
        ubx = self._pack(b.x_upper, b.u_upper, b.d_upper, b.t_upper)
        horizon = [] if tr.free_time else [b.t_lower]
        p_val = np.concatenate([[params[n] for n in tr.ocp.parameters], Win.ravel(order="F"), horizon])
        tic = time.perf_counter()
        lbg, ubg = self._constraint_bounds(params)
        sol = self.solver(x0=np.clip(w0, lbx, ubx), lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg, p=p_val)
        elapsed = time.perf_counter() - tic
        stats = self.solver.stats()
        native = stats.get("return_status", "unknown")
        status = STATUS_MAP.get(native, Status.ERROR)
        w = np.asarray(sol["x"]).ravel()
        if status.ok:
            self._last = w
        X, U, d, T = self._unpack(w, b.t_lower)
        nx = self.shape[0]
        nu_def = np.asarray(sol["lam_g"]).ravel()[: self.n_defects].reshape((nx, -1), order="F")
        return tr.result(
            X=X,
            U=U,
            T=T,
            objective=float(sol["f"]) * tr.ocp.sign if status.ok else None,
            params=params,
            inputs=Win,
            design=d,
            status=status,
            message=native,
            solve_time_s=elapsed,
            iterations=int(stats.get("iter_count", 0)),
            defect_multipliers=nu_def,
            solver_stats={"return_status": native, "solver": self.options.solver},
        )


class CasadiBackend(CollocationBackend):
    """Direct collocation (LGR or trapezoidal) on CasADi with IPOPT."""

    name: ClassVar[str] = "casadi"
    options_model = CasadiOptions
    nlp_field: ClassVar[str] = "ipopt"

    @classmethod
    def available(cls) -> Availability:
        try:
            import casadi
        except ImportError as err:
            return Availability(False, f"casadi does not import: {err}")
        if not casadi.has_nlpsol("ipopt"):
            return Availability(False, "casadi was built without the ipopt plugin")
        return Availability(True, f"casadi {casadi.__version__} with ipopt")

    def _compile(self, spec: OptimalControlSpec, options: CasadiOptions) -> CasadiModel:
        return CasadiModel(spec, options)
