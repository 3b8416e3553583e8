"""The NLP executables the Pyomo backend drives through AMPL NL/SOL files, and their statuses.

No pip package ships Ipopt's executable, but ``pyomo-ripopt`` bundles ``ripopt``, an interior-point
solver with the same AMPL interface, options and return statuses. ``auto`` takes an ``ipopt``
executable on PATH when there is one and the bundled ``ripopt`` otherwise.
"""

from __future__ import annotations

import difflib
import importlib.util
import math
import os
import re
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass
from functools import cache
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

import numpy as np

from gamespec.errors import BackendError
from gamespec.result import Status

SOLVERS = ("ripopt", "ipopt")

STATUS_MAP: dict[str, Status] = {
    "optimal": Status.OPTIMAL,
    "locallyOptimal": Status.OPTIMAL,
    "globallyOptimal": Status.OPTIMAL,
    "feasible": Status.FEASIBLE,
    "infeasible": Status.LOCALLY_INFEASIBLE,
    "locallyInfeasible": Status.LOCALLY_INFEASIBLE,
    "unbounded": Status.UNBOUNDED,
    "maxIterations": Status.ITERATION_LIMIT,
    "maxEvaluations": Status.ITERATION_LIMIT,
    "maxTimeLimit": Status.TIME_LIMIT,
    "internalSolverError": Status.NUMERICAL_ERROR,
    "solverFailure": Status.ERROR,
    "error": Status.ERROR,
}
"""Pyomo's ``TerminationCondition`` (read from the SOL file's solve code) → gamespec's Status. Both
executables are local interior-point solvers: what the SOL file calls infeasible is a converged point
of local infeasibility, so it is ``locally_infeasible``, never a proof that no solution exists."""

PRINT_LEVEL = {"ripopt": 1, "ipopt": 3}
"""The lowest print level at which each executable still reports its iteration count."""

_ITERATIONS = re.compile(r"^\s*(?:iterations:|Number of Iterations\.*:)\s*(\d+)", re.MULTILINE)
_SECONDS = re.compile(r"^\s*(?:wall_time:|Total seconds in IPOPT\s*=)\s*([0-9.eE+-]+)", re.MULTILINE)


@dataclass(frozen=True)
class Executable:
    """An NLP solver executable: its Pyomo solver name, its path and where it came from."""

    name: str
    path: str
    origin: str


def _bundled_ripopt() -> Executable | None:
    spec = importlib.util.find_spec("pyomo_ripopt")
    if spec is None or spec.origin is None:
        return None
    path = Path(spec.origin).parent / "bin" / "ripopt"
    if not (path.is_file() and os.access(path, os.X_OK)):
        return None
    try:
        release = version("pyomo-ripopt")
    except PackageNotFoundError:
        release = "?"
    return Executable("ripopt", str(path), f"bundled with pyomo-ripopt {release}")


def _on_path(name: str) -> Executable | None:
    path = shutil.which(name)
    return Executable(name, path, "on PATH") if path else None


def find_executable(choice: str = "auto") -> Executable:
    """The executable for ``choice`` (``auto``, ``ripopt`` or ``ipopt``); BackendError saying why
    there is none."""
    found = {"ipopt": _on_path("ipopt"), "ripopt": _bundled_ripopt() or _on_path("ripopt")}
    if choice == "auto":
        exe = found["ipopt"] or found["ripopt"]
    elif choice in SOLVERS:
        exe = found[choice]
    else:
        raise BackendError(f"unknown Pyomo NLP solver {choice!r} (use auto, {', '.join(SOLVERS)})")
    if exe is None:
        why = {
            "auto": "pyomo-ripopt's bundled ripopt is missing and no ipopt or ripopt is on PATH",
            "ripopt": "pyomo-ripopt's bundled ripopt is missing and none is on PATH",
            "ipopt": "no ipopt executable on PATH (pip ships none; the bundled ripopt is solver 'ripopt')",
        }
        raise BackendError(why[choice])
    return exe


_LISTED_OPTION = {
    "ripopt": re.compile(r"^\s+([a-z][a-z0-9_]*)=<", re.MULTILINE),
    "ipopt": re.compile(r"^([a-z][a-z0-9_]*)\s", re.MULTILINE),
}
_LIST_FLAG = {"ripopt": "--help", "ipopt": "-="}


@cache
def option_names(exe: Executable) -> frozenset[str]:
    """The options ``exe`` takes as ``key=value``, as it lists them itself (ripopt's ``--help``,
    the AMPL ``-=`` listing of Ipopt's executable); empty when it lists none."""
    try:
        listing = subprocess.run(
            [exe.path, _LIST_FLAG[exe.name]], capture_output=True, text=True, timeout=30, check=False
        )
    except (OSError, subprocess.SubprocessError):
        return frozenset()
    return frozenset(_LISTED_OPTION[exe.name].findall(listing.stdout + listing.stderr))


def check_options(choice: str, options: dict[str, Any]) -> None:
    """ValueError naming the first of ``options`` that the executable for ``choice`` does not list
    (with the nearest name it does), so that no option is silently ignored; nothing to check when
    there is no executable (the solve then says why)."""
    try:
        exe = find_executable(choice)
    except BackendError:
        return
    names = option_names(exe)
    for key in options:
        if names and key not in names:
            near = difflib.get_close_matches(key, names, n=1)
            hint = f"; did you mean {near[0]!r}?" if near else ""
            raise ValueError(f"{exe.name} has no option {key!r}{hint}")


@dataclass(frozen=True)
class Run:
    """One run of an executable on an NL file: Pyomo's reading of the SOL file (None when the run
    was stopped at its wall-clock limit), the log and the seconds the process took."""

    results: Any
    log: str
    seconds: float

    @property
    def stopped(self) -> bool:
        """Whether the process was killed at the wall-clock limit (no SOL file)."""
        return self.results is None


def run_solver(exe: Executable, nl_text: str, options: dict[str, Any], wall_time: float | None = None) -> Run:
    """Run ``exe`` on the NL file ``nl_text`` as Pyomo's AMPL solvers do (``key=value`` on the command
    line and in ``<name>_options``; an ``OF_key`` option in the options file ``<name>.opt`` in the
    working directory, where Ipopt reads every option it has) and read its SOL file with Pyomo's
    reader (duals included); BackendError when it exits with an error or writes no SOL file.

    ``wall_time``: the seconds the process may run; it is killed then (a :attr:`Run.stopped` run).
    The solver's own ``max_wall_time`` is checked once an iteration (2-4 s an iteration on
    definition-heavy models, and after its setup: runs given 300 s ended at 330-420 s, issue 25), so
    only a kill makes the limit one."""
    from pyomo.opt.plugins.sol import ResultsReader_sol

    in_file = {key.removeprefix("OF_"): value for key, value in options.items() if key.startswith("OF_")}
    options = {key: value for key, value in options.items() if not key.startswith("OF_")}
    env = os.environ.copy()
    env[f"{exe.name}_options"] = " ".join(
        f'{key}="{value}"' if isinstance(value, str) and " " in value else f"{key}={value}"
        for key, value in options.items()
    )
    with tempfile.TemporaryDirectory(prefix="gamespec-pyomo-") as tmp:
        nl = Path(tmp) / "model.nl"
        nl.write_text(nl_text)
        if in_file:
            (Path(tmp) / f"{exe.name}.opt").write_text("".join(f"{k} {v}\n" for k, v in in_file.items()))
        cmd = [exe.path, str(nl), "-AMPL", *(f"{key}={value}" for key, value in options.items())]
        tic = time.perf_counter()
        try:
            done = subprocess.run(
                cmd,
                stdout=subprocess.PIPE,
                stderr=subprocess.STDOUT,
                text=True,
                env=env,
                cwd=tmp,
                timeout=None if wall_time is None else max(wall_time, 0.0),
            )
        except subprocess.TimeoutExpired as stopped:
            log = stopped.stdout if isinstance(stopped.stdout, str) else (stopped.stdout or b"").decode()
            return Run(None, log, time.perf_counter() - tic)
        except OSError as err:
            raise BackendError(f"{exe.name} failed to run: {err}") from None
        seconds = time.perf_counter() - tic
        sol = nl.with_suffix(".sol")
        if done.returncode != 0 or not sol.is_file():
            last = (done.stdout.strip().splitlines() or ["no output"])[-1]
            raise BackendError(f"{exe.name} failed to run (exit status {done.returncode}): {last}")
        return Run(ResultsReader_sol()(str(sol), suffixes=["dual"]), done.stdout, seconds)


def pyomo_solver(exe: Executable) -> Any:
    """Pyomo's NL-file solver for ``exe``: the ``ripopt`` plugin (registered by importing
    pyomo_ripopt) or Pyomo's own ``ipopt`` plugin, both AMPL-interface solvers."""
    from pyomo.environ import SolverFactory

    if exe.name == "ripopt" and importlib.util.find_spec("pyomo_ripopt") is not None:
        importlib.import_module("pyomo_ripopt")
    return SolverFactory(exe.name, executable=exe.path)


def status_of(termination: str, message: str) -> Status:
    """gamespec's Status for a Pyomo termination condition; Ipopt's (and ripopt's) 'Solved To
    Acceptable Level' has an optimal solve code but is only feasible to the acceptable tolerances, and
    ripopt reports its wall-time limit ('Maximum CPU Time Exceeded') with the iteration-limit code."""
    status = STATUS_MAP.get(termination, Status.ERROR)
    if "time exceeded" in message.lower():
        return Status.TIME_LIMIT
    if status is Status.OPTIMAL and "acceptable level" in message.lower():
        return Status.FEASIBLE
    return status


def iterations_in(log: str) -> int | None:
    """The iteration count printed by ripopt (``iterations: N``) or Ipopt (``Number of Iterations``)."""
    match = _ITERATIONS.search(log)
    return int(match.group(1)) if match else None


def solver_seconds_in(log: str) -> float | None:
    """The solver's own wall time, printed by ripopt (``wall_time: 0.16s``) or Ipopt 3.14 (``Total
    seconds in IPOPT = 0.16``): the solve time less NL writing and process start."""
    match = _SECONDS.search(log)
    return float(match.group(1)) if match else None


class LinearFeasibility:
    """A feasibility pre-check for models whose constraints are linear once the Vars held by equal
    bounds (parameters, grid inputs, a fixed horizon, fixed end values) are read as the constants
    they are — a linear system's transcription with box bounds, such as ``x'' = u, |u| <= 1`` with
    fixed ends: the feasible set is then a polyhedron, and an LP with no objective (HiGHS, through
    SciPy) decides in milliseconds whether it is empty, a proof of infeasibility where ripopt, which
    has no infeasibility-detection option (Ipopt's ``expect_infeasible_problem``), runs to its
    iteration limit. A model found nonlinear once is not checked again (which constraints are
    nonlinear depends on the structure only)."""

    def __init__(self, model: Any) -> None:
        self.model = model
        self.linear = True

    def _rows(self) -> tuple[list[Any], list[tuple[Any, list[int], list[float], float]]] | None:
        """The constraints' linear rows over the free Vars, or None when one is not linear."""
        from pyomo.environ import Constraint, Var
        from pyomo.repn.standard_repn import generate_standard_repn

        held = [
            v
            for v in self.model.component_data_objects(Var)
            if not v.fixed and v.lb is not None and v.lb == v.ub
        ]
        for v in held:
            v.fix(v.lb)
        try:
            variables: list[Any] = []
            index: dict[int, int] = {}
            rows = []
            for con in self.model.component_data_objects(Constraint, active=True):
                repn = generate_standard_repn(con.body, quadratic=False)
                if not repn.is_linear():
                    return None
                cols = []
                for v in repn.linear_vars:
                    if id(v) not in index:
                        index[id(v)] = len(variables)
                        variables.append(v)
                    cols.append(index[id(v)])
                rows.append((con, cols, [float(c) for c in repn.linear_coefs], float(repn.constant)))
            return variables, rows
        finally:
            for v in held:
                v.unfix()

    def infeasibility(self) -> str | None:
        """Why the model's constraints have no solution at the Vars' current bounds (None when they
        have one, or the model is not linear)."""
        if not self.linear:
            return None
        found = self._rows()
        if found is None:
            self.linear = False
            return None
        variables, rows = found
        if not rows:
            return None
        from scipy.optimize import linprog
        from scipy.sparse import coo_matrix, vstack

        def bounded(value: Any, default: float) -> float:
            return default if value is None else float(value)

        data, at_row, at_col, lower, upper = [], [], [], [], []
        for r, (con, columns, coefs, constant) in enumerate(rows):
            data += coefs
            at_row += [r] * len(columns)
            at_col += columns
            lower.append(bounded(con.lb, -math.inf) - constant)
            upper.append(bounded(con.ub, math.inf) - constant)
        matrix = coo_matrix((data, (at_row, at_col)), shape=(len(rows), len(variables))).tocsr()
        lo, hi = np.array(lower), np.array(upper)
        finite_hi, finite_lo = np.isfinite(hi), np.isfinite(lo)
        answer = linprog(
            np.zeros(len(variables)),
            A_ub=vstack([matrix[finite_hi], -matrix[finite_lo]]),
            b_ub=np.concatenate([hi[finite_hi], -lo[finite_lo]]),
            bounds=[(bounded(v.lb, -math.inf), bounded(v.ub, math.inf)) for v in variables],
            method="highs",
        )
        if answer.status == 2:
            return (
                "the transcribed constraints are linear and have no solution (an LP feasibility check "
                "by HiGHS proves it; the NLP solver was not run): relax the bounds, the end values or "
                "the final time"
            )
        return None
