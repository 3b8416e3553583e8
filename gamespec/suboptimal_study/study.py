"""The ``study`` study: runs a ``pursuit_suboptimal_study`` (Table 2.1, §2.4.4) point by point.

Every point of :func:`gamespec.suboptimal_study.points.study_points` is solved by :func:`evaluate` (the
engagement compiled once per speed and process through the chain, :func:`gamespec.compile_spec`,
and re-solved for each point's P2 position by the parameter maps) and goes through
:func:`gamespec.studies.runner.run_study` into a :class:`~gamespec.studies.store.ResultStore` at the
spec's ``store`` folder, through an executor plugin (``serial``, ``process`` or ``dask``, see
:mod:`gamespec.studies.executors`); points already stored are reused, so solving the file again
resumes where it stopped.

The Result: ``metrics["table"]`` holds one Table 2.1 row per speed, ``arrays`` the per-point
values (NaN where a point has no accepted optimum), ``checks`` the worst simultaneous-capture gap,
re-simulation error (eq. 2.1 integrated under the optimal heading) and defect over the solved
points. Status ``optimal`` when every point solved, ``feasible`` when some were left out of the
averages (no optimum passed the defect check), ``error`` when none solved.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cache
from typing import Any, ClassVar

import numpy as np
from pydantic import BaseModel, ConfigDict, model_validator

from gamespec.metrics import Finite
from gamespec.pursuit import pure_pursuit
from gamespec.pursuit.ocp_generation import trajectory_guess
from gamespec.pursuit.pursuit_curve import constant_heading_pursuit
from gamespec.pursuit.simulation import Players, compiled_integration
from gamespec.result import Result, Status
from gamespec.solving import Solver, compile_spec
from gamespec.studies.point_study import PointStudy, PointStudyModel
from gamespec.studies.runner import StudyRun
from gamespec.studies.store import ResultStore
from gamespec.suboptimal_study.points import DEFECT_TOL, StudyPoint, point_engagement, study_points, summarize
from gamespec.suboptimal_study.spec import SuboptimalStudySpec

POINT_ARRAYS = ("v", "r2", "psi", "t_suboptimal", "t_optimal", "variation_percent")
"""Per-point values copied into ``Result.arrays`` (the plot's scatter)."""

SWEPT = ("v", "r2", "psi")
"""The per-point fields that vary over the grid (what ``gamespec results`` and ``plot`` show)."""

POINT_CHECKS = {
    "max_simultaneous_capture_gap": "simultaneous_capture_gap",
    "max_resimulated_capture_time_error": "resimulated_capture_time_error",
    "max_defect": "max_defect",
}
"""``Result.checks`` entry → the per-point check whose maximum over the solved points it holds."""


@cache
def _solver(v: float, r1: float, u: float, eps: float, method: str, backend: str) -> Solver:
    """The study's engagement at one speed through the chain, compiled once per process: P2's
    position is a runtime parameter (:data:`MOVED`), far away at compile time (it sets nothing
    but the values of the compiled OCP's parameters). Its solves run the ``resimulation`` analysis,
    the one whose check (:data:`POINT_CHECKS`) the table reads."""
    reference = StudyPoint(v, 10 * r1, 0.5 * np.pi, r1, u, eps, (method,), backend)
    return compile_spec(point_engagement(reference), backend, analyses=["resimulation"])


MOVED = ("pursuers.1.position.0", "pursuers.1.position.1")
"""The engagement's runtime parameters a study point sets: P2's position."""


def _first_accepted(point: StudyPoint, parameters: dict[str, float], guess: Result) -> tuple[int, Result]:
    """Solve with each of the point's methods in turn; the first that passes the defect check (or
    the last one tried) and its index."""
    for attempt, method in enumerate(point.methods):
        solver = _solver(point.v, point.r1, point.u, point.eps, method, point.backend)
        result = solver.solve(parameters=parameters, guess=guess)
        if _accepted(result):
            return attempt, result
    return len(point.methods) - 1, result


def _accepted(result: Result) -> bool:
    """Whether a point's solve is an optimum that passes the defect check."""
    defect = result.checks.get("max_defect")
    return result.ok and result.t_final is not None and defect is not None and defect < DEFECT_TOL


def evaluate(point: StudyPoint) -> dict[str, Any]:
    """Suboptimal and optimal capture times of one point (the row the store keeps): the optimum is
    the chain's re-solve of the engagement (its parameter map, the compiled OCP, its inverse map
    with the re-simulation check, by the compiled integrator: a study is a loop of them,
    :func:`~gamespec.pursuit.simulation.compiled_integration`), started from the suboptimal path in
    closed form."""
    with compiled_integration():
        return _evaluated(point)


def _evaluated(point: StudyPoint) -> dict[str, Any]:
    spec = point_engagement(point)
    players = Players.from_spec(spec)
    compiled = _solver(point.v, point.r1, point.u, point.eps, point.methods[0], point.backend)
    red = compiled.steps[0].inverse.reduction  # the names and frame of every point's reduction
    choice = pure_pursuit.suboptimal_heading(players)
    traj = constant_heading_pursuit(players, choice.heading)
    guess = trajectory_guess(red, traj)
    parameters = dict(zip(MOVED, spec.pursuers[1].position, strict=True))
    attempt, result = _first_accepted(point, parameters, guess)
    row: dict[str, Any] = {
        "v": point.v,
        "r2": point.r2,
        "psi": point.psi,
        "status": result.status.value,
        "t_suboptimal": traj.capture_time,
        "heading_suboptimal": choice.heading,
        "solve_time_s": result.solve_time_s,
        "attempt": attempt,
        "max_defect": result.checks.get("max_defect"),
    }
    if not _accepted(result) or result.t_final is None:
        return row
    return row | {
        "t_optimal": result.t_final,
        "variation_percent": 100.0 * (result.t_final - traj.capture_time) / result.t_final,
        "simultaneous_capture_gap": result.metrics["simultaneous_capture_gap"],
        "resimulated_capture_time_error": result.checks["resimulated_capture_time_error"],
    }


class StoredRow(BaseModel):
    """A stored point of the Table 2.1 study (:func:`evaluate`'s row), as it must be to be reused."""

    model_config = ConfigDict(extra="allow")

    v: Finite
    r2: Finite
    psi: Finite
    status: str
    max_defect: float | None = None
    t_optimal: float | None = None
    variation_percent: float | None = None
    simultaneous_capture_gap: float | None = None
    resimulated_capture_time_error: float | None = None

    @model_validator(mode="after")
    def _solved_rows_are_complete(self) -> StoredRow:
        missing = [name for name in SOLVED_FIELDS if getattr(self, name) is None]
        if self.variation_percent is not None and missing:
            raise ValueError(f"a solved point lacks {', '.join(missing)}")
        return self


SOLVED_FIELDS = ("max_defect", "t_optimal", "simultaneous_capture_gap", "resimulated_capture_time_error")
"""What a solved point's row carries besides its variation (the checks are maxima over them)."""


class StudyModel(PointStudyModel[SuboptimalStudySpec]):
    """The Table 2.1 study ready to run (or resume) into its store."""

    row_model = StoredRow

    def points(self) -> dict[str, Any]:
        return study_points(self.spec)

    def point_function(self) -> Callable[[Any], dict[str, Any]]:
        return evaluate

    def prepare(self, store: ResultStore) -> None:
        store.set_meta("study", {"type": "sweep", "problem": self.spec.name, "parameters": list(SWEPT)})

    def result(self, rows: list[dict[str, Any]], run: StudyRun) -> Result:
        solved = [r for r in rows if "variation_percent" in r]
        status, message = _outcome(len(rows), len(solved))
        return Result(
            status=status,
            message=message,
            arrays={name: np.array([r.get(name, np.nan) for r in rows]) for name in POINT_ARRAYS},
            checks={name: max((r[key] for r in solved), default=None) for name, key in POINT_CHECKS.items()},
            metrics={
                "table": summarize(rows),
                "points": len(rows),
                "solved": len(solved),
                "computed": run.computed,
                "store": str(self.spec.store),
            },
        )


def _outcome(points: int, solved: int) -> tuple[Status, str]:
    if points and solved == points:
        return Status.OPTIMAL, f"all {points} points solved"
    if solved:
        left_out = points - solved
        return Status.FEASIBLE, (
            f"{left_out} of {points} points left out of the averages "
            f"(no optimum with a defect below {DEFECT_TOL:g})"
        )
    return Status.ERROR, f"none of the {points} points solved"


class SuboptimalStudy(PointStudy):
    """Runs the Table 2.1 study (see module doc); each point's OCP is solved on ``ocp_backend``."""

    name: ClassVar[str] = "study"
    kinds: ClassVar[frozenset[str]] = frozenset({"pursuit_suboptimal_study"})
    model: ClassVar[type[PointStudyModel[Any]]] = StudyModel
