"""The ``pyomo`` backend: an ``optimal_control`` spec as a Pyomo model, solved by an NLP executable
through AMPL NL/SOL files (the bundled ``ripopt``, or ``ipopt`` when one is on PATH).

The model (:mod:`gamespec_pyomo.model`) is the CasADi backend's discretization written in Pyomo and
is built once, and so is its NL file (:mod:`gamespec_pyomo.nlfile`). A solve fixes the parameters,
the grid inputs and a fixed horizon through equal bounds, sets the bounds, starts from the last
solution (or from a guess Result of any backend), rewrites the NL file's bounds and start segments
and runs the executable. Costates come from the defect multipliers the SOL file returns (Suffix
``dual``), as in the CasADi backend. A solve is bounded by ``max_wall_time`` on the wall clock (the
process is killed there); an infeasible linear transcription is found by an LP before the solver
runs, a nonlinear one by the elastic problem after it failed (:mod:`gamespec_pyomo.feasibility`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import Field, ValidationInfo, field_validator

from gamespec.compiling import Availability, Inputs
from gamespec.compiling.collocation import IPOPT_DEFAULTS, CollocationBackend, CollocationModel
from gamespec.errors import BackendError
from gamespec.ocp.compiled_checks import prepare as prepare_checks
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.ocp.transcription import Bounds, Transcription
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel
from gamespec.specs.ocp import OptimalControlSpec
from gamespec_pyomo.feasibility import (
    ELASTIC_FLOOR_S,
    ELASTIC_SHARE,
    PROBE_ITERATIONS,
    ElasticFeasibility,
    Verdict,
    stagnated,
    wants_verdict,
)
from gamespec_pyomo.model import build_model
from gamespec_pyomo.nlfile import NLFile
from gamespec_pyomo.solvers import (
    PRINT_LEVEL,
    LinearFeasibility,
    Run,
    check_options,
    find_executable,
    iterations_in,
    pyomo_solver,
    run_solver,
    solver_seconds_in,
    status_of,
)


class PyomoOptions(StrictModel):
    """Options block ``solver.options.pyomo``."""

    solver: Literal["auto", "ripopt", "ipopt"] = Field(
        "auto", description="NLP executable: auto takes ipopt on PATH, else the bundled ripopt."
    )
    tol: float = Field(1e-8, gt=0, description="The solver's tol.")
    max_iter: int = Field(3000, ge=1, description="The NLP solver's iteration limit.")
    max_wall_time: float = Field(
        300.0,
        gt=0,
        description="Wall-clock limit of a solve in seconds, NL file writing included: the solver gets"
        " 90% of what is left as its own limit (it checks it once an iteration) and is killed at the"
        " limit (status time_limit).",
    )
    options: dict[str, Any] = Field(
        default_factory=dict, description="Further solver options (key=value on its command line)."
    )
    warm_start: bool = Field(True, description="Re-solves start from the previous solution.")

    @field_validator("options")
    @classmethod
    def _listed_by_the_solver(cls, options: dict[str, Any], info: ValidationInfo) -> dict[str, Any]:
        """Every option is one the executable lists (ripopt would ignore an unknown one)."""
        if options and "solver" in info.data:
            check_options(info.data["solver"], options)
        return options


SOLVER_SHARE = 0.9
"""The share of the time left when the solver starts that it gets as its own ``max_wall_time``: it
stops itself (with its iterate) before the process is killed at the limit."""


def _bound(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def _outcome(run: Run) -> tuple[Status, str, str]:
    """A finished run's Status, termination condition and the solver's message."""
    termination = str(run.results.solver.termination_condition)
    # Pyomo's SOL reader stores the solver's message with ':' escaped as '\x3a'.
    message = str(run.results.solver.message or termination).replace("\\x3a", ":")
    return status_of(termination, message), termination, message


def _fix(var: Any, value: float) -> None:
    """Hold ``var`` at ``value`` by equal bounds (a fixed Var would be a constant of the NL file)."""
    var.setlb(float(value))
    var.setub(float(value))
    var.set_value(float(value))


class PyomoModel(CollocationModel):
    """The Pyomo model and the solver that runs on it, built once."""

    options: PyomoOptions

    def __init__(
        self, spec: OptimalControlSpec, options: PyomoOptions, parsed: SymbolicOcp | None = None
    ) -> None:
        import pyomo.environ as pyo

        self.pyo = pyo
        self.tr = Transcription(spec, parsed)
        prepare_checks(self.tr)
        self.options = options
        self.executable = find_executable(options.solver)
        self.model = build_model(self.tr, self.tr.ocp.parameter_values())
        self.nl = NLFile(self.model)
        self.linear = LinearFeasibility(self.model)
        self.elastic = ElasticFeasibility(self.model)
        self._elastic_nl: NLFile | None = None
        self._solved = False

    def _set_data(self, params: Mapping[str, float], Win: np.ndarray) -> None:
        """Fix the parameters and the grid inputs at their values for this solve."""
        m = self.model
        for name, value in params.items():
            _fix(m.p[name], value)
        for (i, col), var in m.w.items():
            _fix(var, Win[i, col])

    def _set_bounds(self, b: Bounds) -> None:
        m = self.model
        for (i, n), var in m.X.items():
            var.setlb(_bound(b.x_lower[i, n]))
            var.setub(_bound(b.x_upper[i, n]))
        for (j, c), var in m.U.items():
            var.setlb(_bound(b.u_lower[j, c]))
            var.setub(_bound(b.u_upper[j, c]))
        for name, lo, hi in zip(self.tr.ocp.design, b.d_lower, b.d_upper, strict=True):
            m.d[name].setlb(_bound(lo))
            m.d[name].setub(_bound(hi))
        if self.tr.free_time:
            m.T.setlb(b.t_lower)
            m.T.setub(b.t_upper)
        else:
            _fix(m.T, b.t_lower)

    def _set_integral_bounds(self, params: dict[str, float]) -> None:
        """The integral constraints' bounds for this solve, as bounds of the Var each integral equals
        (so the NL file's constraint ranges stay structural, :mod:`gamespec_pyomo.nlfile`)."""
        for r, (lo, hi) in enumerate(self.tr.ocp.integral_bounds(params)):
            var = self.model.integral_value[r]
            var.setlb(_bound(lo))
            var.setub(_bound(hi))

    def _set_start(self, X: np.ndarray, U: np.ndarray, d: np.ndarray, T: float, b: Bounds) -> None:
        m = self.model
        for name, value in zip(self.tr.ocp.design, np.clip(d, b.d_lower, b.d_upper), strict=True):
            m.d[name].set_value(float(value))
        X = np.clip(X, b.x_lower, b.x_upper)
        U = np.clip(U, b.u_lower, b.u_upper)
        for (i, n), var in m.X.items():
            var.set_value(float(X[i, n]))
        for (j, c), var in m.U.items():
            var.set_value(float(U[j, c]))
        if self.tr.free_time:
            m.T.set_value(float(np.clip(T, b.t_lower, b.t_upper)))

    def _values(self) -> tuple[np.ndarray, np.ndarray, float]:
        m, tr = self.model, self.tr
        X = np.array([[m.X[i, n].value for n in range(tr.grid.n_nodes)] for i in range(tr.n_x)], float)
        k = len(tr.grid.eval_index)
        U = np.array([[m.U[j, c].value for c in range(k)] for j in range(tr.n_u)], float).reshape(tr.n_u, k)
        return X, U, float(self.pyo.value(m.T))

    def _defect_multipliers(self) -> np.ndarray | None:
        m = self.model
        if not all(con in m.dual for con in m.defect.values()):
            return None
        rows = len(m.defect) // self.tr.n_x
        duals = np.array([[m.dual[m.defect[i, r]] for r in range(rows)] for i in range(self.tr.n_x)], float)
        scaled: np.ndarray = duals / self.tr.compiled_scaling.states[:, None]  # rows divided by the scales
        return scaled

    def _integral_multipliers(self) -> np.ndarray | None:
        """The multipliers of the integral constraints as the CasADi backend has them (of the row
        ``T q^T g``: Pyomo's constraint reads ``value - T q^T g == 0``, hence the sign)."""
        m = self.model
        if not all(con in m.dual for con in m.integral.values()):
            return None
        return np.array([-m.dual[m.integral[r]] for r in range(len(m.integral))], dtype=float)

    def _solver_options(self, remaining: float) -> dict[str, Any]:
        name = self.executable.name
        opts = {"tol": self.options.tol, "max_iter": self.options.max_iter, "print_level": PRINT_LEVEL[name]}
        opts["max_wall_time"] = max(SOLVER_SHARE * remaining, 1e-3)
        if name == "ipopt":
            # Through Ipopt's options file (Pyomo's OF_ prefix), which takes every Ipopt option.
            opts |= {f"OF_{k}": v for k, v in IPOPT_DEFAULTS.items() if k not in self.options.options}
        return opts | self.options.options

    def _execute(self, deadline: float, text: str, max_iter: int | None = None) -> Run:
        """Run the executable on the NL file ``text`` (the model's, with its starting point), killed
        at ``deadline`` (a ``time.perf_counter`` value), at most ``max_iter`` iterations when given;
        load the solution it finds."""
        remaining = deadline - time.perf_counter()
        options = self._solver_options(remaining) | ({} if max_iter is None else {"max_iter": max_iter})
        run = run_solver(self.executable, text, options, remaining)
        if not run.stopped and len(run.results.solution) > 0:
            self.nl.load(run.results.solution(0))
        return run

    def _probed(self, deadline: float, text: str) -> tuple[Run, str | None]:
        """The solver's run on ``text``, by way of a probe (:mod:`gamespec_pyomo.feasibility`)
        where ripopt, which has no infeasibility detection, may run many iterations: a first run of
        at most :data:`PROBE_ITERATIONS`; when it ends before them, it is the run (the same
        iterates as one run); when it stops there with the constraint violation stagnant, the
        elastic problem decides from its point: a locally infeasible verdict's message is returned
        with the probe's run; else the full run follows from the same start."""
        full = int(self._solver_options(1.0)["max_iter"])
        if self.executable.name != "ripopt" or full <= PROBE_ITERATIONS:
            return self._execute(deadline, text), None
        before = self.elastic.violation()
        probe = self._execute(deadline, text, PROBE_ITERATIONS)
        if probe.stopped or len(probe.results.solution) == 0:
            return probe, None
        if _outcome(probe)[0] is not Status.ITERATION_LIMIT:
            return probe, None
        after = self.elastic.violation()
        if stagnated(before, after):
            verdict = self._verdict(probe, deadline)
            if verdict is not None and verdict.infeasible:
                note = (
                    f"ripopt's first {PROBE_ITERATIONS} iterations left the l1 norm of the constraint"
                    f" violation at {after:.3g} (from {before:.3g} at the start)"
                )
                return probe, f"{note}; {verdict.message()}"
        return self._execute(deadline, text), None

    def _verdict(self, run: Run, limit: float) -> Verdict | None:
        """The elastic problem's verdict from the model's values, in at most :data:`ELASTIC_SHARE`
        of ``run``'s seconds (or :data:`ELASTIC_FLOOR_S`), never past ``limit``."""
        deadline = min(limit, time.perf_counter() + max(ELASTIC_SHARE * run.seconds, ELASTIC_FLOOR_S))
        return self.elastic.verdict(lambda e: self._solve_elastic(e, deadline))

    def _solve_elastic(self, elastic: Any, deadline: float) -> bool:
        """Run the solver on the elastic model (:mod:`gamespec_pyomo.feasibility`) until
        ``deadline``; True when it ends at a local minimum (its solution then loaded)."""
        if self._elastic_nl is None:
            self._elastic_nl = NLFile(elastic)
        remaining = deadline - time.perf_counter()
        if remaining <= 0:
            return False
        run = run_solver(self.executable, self._elastic_nl.text(), self._solver_options(remaining), remaining)
        if run.stopped or len(run.results.solution) == 0:
            return False
        termination = str(run.results.solver.termination_condition)
        message = str(run.results.solver.message or termination)
        if not status_of(termination, message).ok:
            return False
        self._elastic_nl.load(run.results.solution(0))
        return True

    def solve_once(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        tr, m = self.tr, self.model
        params = tr.ocp.parameter_values(parameters)
        Win = tr.input_values(params, inputs)
        self._set_data(params, Win)
        b = tr.bounds(params)
        self._set_bounds(b)
        self._set_integral_bounds(params)
        if guess is not None or not (self._solved and self.options.warm_start):
            start = tr.guess(params, guess)
            self._set_start(start.X, start.U, start.d, start.T, b)
        m.dual.clear()
        tic = time.perf_counter()
        why = self.linear.infeasibility()
        if why is not None:
            stats = {"solver": "highs (LP feasibility check)"}
            return self._unsolved(params, Win, Status.INFEASIBLE, why, time.perf_counter() - tic, 0, stats)
        limit = tic + self.options.max_wall_time
        run, decided = self._probed(limit, self.nl.text())
        elapsed = time.perf_counter() - tic
        if run.stopped:
            return self._stopped(params, Win, run, elapsed)
        results, log = run.results, run.log
        loaded = len(results.solution) > 0
        self._solved = self._solved or loaded
        status, termination, message = _outcome(run)
        if decided is not None:
            status, message = Status.LOCALLY_INFEASIBLE, decided
        elif wants_verdict(status, message):
            verdict = self._verdict(run, limit)
            elapsed = time.perf_counter() - tic
            if verdict is not None and verdict.infeasible:
                status, message = Status.LOCALLY_INFEASIBLE, f"{message}; {verdict.message()}"
        X, U, T = self._values()
        return tr.result(
            X=X,
            U=U,
            T=T,
            objective=float(self.pyo.value(m.objective)) * tr.ocp.sign if loaded else None,
            params=params,
            inputs=Win,
            design=np.array([m.d[n].value for n in tr.ocp.design], dtype=float),
            status=status,
            message=message,
            solve_time_s=elapsed,
            iterations=iterations_in(log),
            defect_multipliers=self._defect_multipliers() if loaded else None,
            integral_multipliers=self._integral_multipliers() if loaded else None,
            solver_stats={
                "solver": self.executable.name,
                "executable": self.executable.path,
                "termination_condition": termination,
                "process_time_s": run.seconds,
                "solver_time_s": solver_seconds_in(log),
            },
        )

    def _stopped(self, params: dict[str, float], Win: np.ndarray, run: Run, elapsed: float) -> Result:
        """The Result of a run killed at the wall-clock limit: the starting point, no objective."""
        name = self.executable.name
        message = (
            f"{name} stopped at the wall-clock limit of {self.options.max_wall_time:g} s"
            " (solver.options.pyomo.max_wall_time)"
        )
        stats = {"solver": name, "executable": self.executable.path, "process_time_s": run.seconds}
        return self._unsolved(params, Win, Status.TIME_LIMIT, message, elapsed, iterations_in(run.log), stats)

    def _unsolved(
        self,
        params: dict[str, float],
        Win: np.ndarray,
        status: Status,
        message: str,
        elapsed: float,
        iterations: int | None,
        stats: dict[str, Any],
    ) -> Result:
        """A Result with no solution (no objective): the model's current values, ``status`` and why."""
        X, U, T = self._values()
        return self.tr.result(
            X=X,
            U=U,
            T=T,
            objective=None,
            params=params,
            inputs=Win,
            status=status,
            message=message,
            solve_time_s=elapsed,
            iterations=iterations,
            solver_stats=stats,
        )


class PyomoBackend(CollocationBackend[PyomoOptions]):
    """Direct collocation (LGR or trapezoidal) as a Pyomo model, solved by ripopt or ipopt."""

    name: ClassVar[str] = "pyomo"
    options_model = PyomoOptions
    nlp_field: ClassVar[str] = "options"
    features: ClassVar[frozenset[str]] = CollocationBackend.features | {
        "tables",
        "interior_points",
        "measurements",
        "free_initial_time",
    }

    @classmethod
    def available(cls) -> Availability:
        try:
            from pyomo.version import version

            exe = find_executable("auto")
            runs = pyomo_solver(exe).available(exception_flag=False)
        except ImportError as err:
            return Availability(False, f"pyomo does not import: {err}")
        except BackendError as err:
            return Availability(False, str(err))
        if not runs:
            return Availability(False, f"{exe.name} at {exe.path} does not run")
        return Availability(True, f"pyomo {version} with {exe.name} ({exe.origin})")

    def _compile(self, spec: OptimalControlSpec, options: PyomoOptions) -> PyomoModel:
        return PyomoModel(spec, options)
