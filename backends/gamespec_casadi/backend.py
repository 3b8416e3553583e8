"""The ``casadi`` backend: an ``optimal_control`` spec as a CasADi NLP by direct collocation.

The NLP is built once from the backend-neutral :class:`~gamespec.ocp.transcription.Transcription`
(:mod:`gamespec_casadi.nlp`: decision variables ``[vec(X / s_x); vec(U / s_u); d; T]``, s the scale
factors, d the design variables; defects ``D X - T W F`` with ``F`` from one per-point function; the
problem's parameters, the grid inputs and a fixed horizon as NLP parameters ``p = [params; vec(Win);
T]``), so a re-solve with new values reuses the solver and warm-starts from the last solution. By
default (``graph: assembled``) IPOPT gets derivative functions assembled from the per-point
function's (:mod:`gamespec_casadi.assembly`); ``graph: sx`` and ``graph: mx`` let CasADi
differentiate the whole NLP, on one flat SX graph or on the MX graph around the mapped function.
"""

from __future__ import annotations

import time
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import Field, ValidationInfo, field_validator

from gamespec.compiling import Availability, Inputs
from gamespec.compiling.collocation import IPOPT_DEFAULTS, CollocationBackend, CollocationModel
from gamespec.errors import BackendError
from gamespec.ocp.compiled_checks import prepare as prepare_checks
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.ocp.transcription import Guess, Transcription
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.symbolic.library import casadi_library

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
    max_iter: int = Field(3000, ge=1, description="IPOPT's iteration limit.")
    max_wall_time: float = Field(300.0, gt=0, description="IPOPT's wall-time limit in seconds.")
    ipopt: dict[str, Any] = Field(default_factory=dict, description="Further IPOPT options.")
    warm_start: bool = Field(True, description="Re-solves start from the previous solution.")
    graph: Literal["assembled", "sx", "mx"] = Field(
        "assembled",
        description="How the NLP's derivatives are built. 'assembled' (IPOPT): the per-point Jacobian"
        " and Hessian mapped over the points and summed with constant sparse matrices (at N = 1000 a"
        " build 5-20x faster than 'sx', within the first IPOPT solve, iterations within a few per cent"
        " of 'sx'; other NLP solvers get 'mx'); 'sx': CasADi differentiates one flat SX graph (the"
        " fastest iterations, a build that grows to seconds at large N); 'mx': CasADi differentiates"
        " the MX graph around the mapped point function (fast build, iterations 1.5-3x slower).",
    )

    @field_validator("ipopt")
    @classmethod
    def _known_to_ipopt(cls, ipopt: dict[str, Any], info: ValidationInfo) -> dict[str, Any]:
        """``ipopt`` holds options IPOPT itself knows and accepts (checked against its own list)."""
        if ipopt and info.data.get("solver") == "ipopt":
            from gamespec_casadi.ipopt_options import check_ipopt_options

            check_ipopt_options(ipopt)
        return ipopt


def nlp_solver(nlp: Any, options: CasadiOptions) -> Any:
    """CasADi's ``nlpsol`` on a :class:`~gamespec_casadi.nlp.CollocationNlp`: with the assembled
    derivative functions for IPOPT when ``graph`` is ``assembled``, else CasADi's own AD of the
    closed NLP."""
    import casadi as ca

    ipopt = {"print_level": 0, "sb": "yes", "tol": options.tol, "max_iter": options.max_iter}
    ipopt["max_wall_time"] = options.max_wall_time
    # NaN in a function evaluation ends as the status numerical_error; CasADi's own warnings about it
    # (and about the parameter multipliers lam_p, which nothing reads) would be extra lines on stderr
    # (README, "Bad input": one line). So would its check of the inputs (an overconstrained NLP is a
    # warning there): CasadiModel.solve_once makes the same checks and says them in the Result.
    nlp_opts: dict[str, Any] = {
        "ipopt": ipopt | IPOPT_DEFAULTS | options.ipopt,
        "print_time": False,
        "show_eval_warnings": False,
        "calc_lam_p": False,
        "inputs_check": False,
    }
    if options.graph == "assembled" and options.solver == "ipopt":
        from gamespec_casadi.assembly import assembled_nlp

        assembled = assembled_nlp(nlp)
        problem, nlp_opts = assembled.nlp, nlp_opts | assembled.derivatives
    else:
        problem = nlp.closed()
    return ca.nlpsol("gamespec", options.solver, problem, nlp_opts)


def ill_posed(lbx: np.ndarray, ubx: np.ndarray, lbg: np.ndarray, ubg: np.ndarray) -> str:
    """What CasADi's own check of an NLP's bounds finds (turned off in :func:`nlp_solver`, where it
    prints): a BackendError for a lower bound above its upper one (the transcription's bug: the
    spec orders every bound at load); the note that the NLP has more equality rows than variables
    (every bound fixing a control, say), else ''."""
    if np.any(lbx > ubx) or np.any(lbg > ubg):
        raise BackendError("the NLP has a lower bound above its upper bound")
    equalities = int(np.sum(lbx == ubx) + np.sum(lbg == ubg))
    if equalities > len(lbx):
        return f"overconstrained: {equalities} equalities (fixed variables included) for {len(lbx)} variables"
    return ""


class CasadiModel(CollocationModel):
    """The NLP and its solver, built once."""

    options: CasadiOptions

    def __init__(
        self, spec: OptimalControlSpec, options: CasadiOptions, parsed: SymbolicOcp | None = None
    ) -> None:
        import casadi as ca

        from gamespec_casadi.nlp import collocation_nlp

        if not ca.has_nlpsol(options.solver):
            raise BackendError(f"casadi has no NLP solver plugin {options.solver!r}")
        self.ca = ca
        self.tr = tr = Transcription(spec, parsed)
        prepare_checks(tr)
        self.options = options
        self.sx, self.su = tr.compiled_scaling.states, tr.compiled_scaling.controls
        outer = ca.SX if options.graph == "sx" else ca.MX
        nlp = collocation_nlp(tr, casadi_library(ca), outer, self.sx, self.su)
        self.n_defects, self.lbg, self.ubg = nlp.n_defects, nlp.lbg, nlp.ubg
        self.solver = nlp_solver(nlp, options)
        self.shape = (tr.n_x, tr.grid.n_nodes, tr.n_u, len(tr.grid.eval_index))
        self._last: np.ndarray | None = None
        self._kept: tuple[dict[str, float], tuple[Any, ...]] | None = None
        self._last_multipliers: dict[str, Any] = {}
        """The multipliers of the last solution, the warm start's with ``_last`` (IPOPT reads them
        with ``warm_start_init_point: yes``, and ignores them otherwise)."""

    def pack(self, X: np.ndarray, U: np.ndarray, d: np.ndarray, T: float) -> np.ndarray:
        """The NLP's variables: X and U divided by their scale factors (also the joint game
        scheme's way in, :mod:`gamespec.games.joint`)."""
        parts = [(X / self.sx[:, None]).ravel(order="F"), (U / self.su[:, None]).ravel(order="F"), d]
        return np.concatenate([*parts, [T]] if self.tr.free_time else parts)

    def _unpack(self, w: np.ndarray, params_T: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        nx, n, nu, k = self.shape
        X = w[: nx * n].reshape((nx, n), order="F") * self.sx[:, None]
        U = w[nx * n : nx * n + nu * k].reshape((nu, k), order="F") * self.su[:, None]
        d = w[nx * n + nu * k : nx * n + nu * k + self.tr.n_d]
        T = float(w[-1]) if self.tr.free_time else params_T
        return X, U, d, T

    def constraint_bounds(self, params: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
        """``lbg, ubg`` with the integral constraints' bounds (the last rows of g) for ``params``
        (also read by the joint game scheme)."""
        n = len(self.tr.ocp.running_structure.integrands)
        if not n:
            return self.lbg, self.ubg
        lbg, ubg = self.lbg.copy(), self.ubg.copy()
        lbg[-n:], ubg[-n:] = np.array(self.tr.ocp.integral_bounds(params)).T
        return lbg, ubg

    def _numbers(self, parameters: dict[str, float] | None) -> tuple[Any, ...]:
        """The parameter values of a solve at ``parameters``, its variable and constraint bounds and
        what :func:`ill_posed` says of them ``(params, bounds, lbx, ubx, lbg, ubg, posed)``, kept for
        the last ``parameters`` (a game's best responses re-solve at the same values with new grid
        inputs)."""
        given = dict(parameters or {})
        if self._kept is not None and self._kept[0] == given:
            return self._kept[1]
        tr = self.tr
        params = tr.ocp.parameter_values(parameters)
        b = tr.bounds(params)
        lbx = self.pack(b.x_lower, b.u_lower, b.d_lower, b.t_lower)
        ubx = self.pack(b.x_upper, b.u_upper, b.d_upper, b.t_upper)
        lbg, ubg = self.constraint_bounds(params)
        numbers = (params, b, lbx, ubx, lbg, ubg, ill_posed(lbx, ubx, lbg, ubg))
        self._kept = (given, numbers)
        return numbers

    def solve_once(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        tr = self.tr
        params, b, lbx, ubx, lbg, ubg, posed = self._numbers(parameters)
        Win = tr.input_values(params, inputs)
        multipliers: dict[str, np.ndarray] = {}
        if guess is None and self._last is not None and self.options.warm_start:
            w0, multipliers = self._last, self._last_multipliers
        else:
            start: Guess = tr.guess(params, guess)
            w0 = self.pack(start.X, start.U, start.d, start.T)
        horizon = [] if tr.free_time else [b.t_lower]
        p_val = np.concatenate([[params[n] for n in tr.ocp.parameters], Win.ravel(order="F"), horizon])
        tic = time.perf_counter()
        sol = self.solver(
            x0=np.clip(w0, lbx, ubx), lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg, p=p_val, **multipliers
        )
        elapsed = time.perf_counter() - tic
        stats = self.solver.stats()
        native = stats.get("return_status", "unknown")
        status = STATUS_MAP.get(native, Status.ERROR)
        if posed and not status.ok:
            native = f"{native} ({posed})"
        w = np.asarray(sol["x"]).ravel()
        if status.ok:
            self._last = w
            self._last_multipliers = {"lam_x0": sol["lam_x"], "lam_g0": sol["lam_g"]}
        X, U, d, T = self._unpack(w, b.t_lower)
        nx = self.shape[0]
        lam_g = np.asarray(sol["lam_g"]).ravel()
        # the defect rows of state i are divided by its scale (gamespec.ocp.scaling)
        nu_def = lam_g[: self.n_defects].reshape((nx, -1), order="F") / self.sx[:, None]
        n_int = len(tr.ocp.running_structure.integrands)
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
            integral_multipliers=lam_g[len(lam_g) - n_int :],
            solver_stats={"return_status": native, "solver": self.options.solver},
        )


class CasadiBackend(CollocationBackend[CasadiOptions]):
    """Direct collocation (LGR or trapezoidal) on CasADi with IPOPT."""

    name: ClassVar[str] = "casadi"
    options_model = CasadiOptions
    nlp_field: ClassVar[str] = "ipopt"
    features: ClassVar[frozenset[str]] = CollocationBackend.features | {
        "tables",
        "interior_points",
        "measurements",
        "free_initial_time",
    }

    @classmethod
    def available(cls) -> Availability:
        try:
            import casadi
        except ImportError as err:
            return Availability(False, f"casadi does not import: {err}")
        if not casadi.has_nlpsol("ipopt"):
            return Availability(False, "casadi was built without the ipopt plugin")
        return Availability(True, f"casadi {casadi.CasadiMeta.version()} with ipopt")

    def _compile(self, spec: OptimalControlSpec, options: CasadiOptions) -> CasadiModel:
        return CasadiModel(spec, options)
