"""The ``rcs_study`` study: runs an ``rcs_multi_obstacle_study`` (Fig. 6.11) point by point
through :func:`gamespec.studies.runner.run_study` into a :class:`~gamespec.studies.store.ResultStore`
at the spec's ``store`` (points already stored are reused, so solving again resumes).

The Result: ``metrics.table`` (one row per (N, α), :func:`gamespec.rcs.study_points.summarize`),
``metrics.layout`` (the obstacles' x_i, y_i(0) and directions per N), ``arrays`` the kept paths.
Status ``optimal`` when every point solved, ``feasible`` when some did not, ``error`` when none did.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from functools import lru_cache
from typing import Any, ClassVar, cast

import numpy as np
from pydantic import BaseModel, ConfigDict, model_validator

from gamespec.analyses import for_study
from gamespec.loader import spec_from_dict
from gamespec.metrics import Finite
from gamespec.rcs.report import Rows, point_line
from gamespec.rcs.study_points import (
    HEADLINE,
    PARAMETERS,
    StudyPoint,
    arrays,
    layout,
    point_problem,
    study_points,
    summarize,
)
from gamespec.rcs.study_spec import RcsStudySpec
from gamespec.rcs.transform import starting_point
from gamespec.result import Result, Status
from gamespec.solving import Solver, compile_spec
from gamespec.specs.ocp import GuessSpec, OptimalControlSpec
from gamespec.studies.point_study import PointStudy, PointStudyModel
from gamespec.studies.report import study_summary
from gamespec.studies.runner import StudyRun
from gamespec.studies.store import ResultStore

TABLE_ANALYSES = ("monte_carlo",)
"""What the table needs of each point's analyses: the collision probability."""


@lru_cache(maxsize=4)
def compiled_point(study: str, obstacles: int) -> tuple[Solver, tuple[Result, ...]]:
    """The problem of ``obstacles`` obstacles compiled once for every α (a runtime parameter,
    mapped through the rcs transform) and its starting points, one per guess of the study (JSON
    ``study``): the points of one N re-solve this model (kept per process, so each worker of a
    parallel executor compiles it once)."""
    spec = RcsStudySpec.model_validate_json(study)
    data = point_problem(spec, obstacles, spec.alphas[0], spec.guesses[0])
    solver = compile_spec(
        spec_from_dict(data), spec.ocp_backend, analyses=for_study(spec.analyses, TABLE_ANALYSES)
    )
    target = cast(OptimalControlSpec, solver.target_spec)
    starts = tuple(
        starting_point(target, GuessSpec.model_validate(point_problem(spec, obstacles, 0.0, a)["guess"]))
        for a in spec.guesses
    )
    return solver, starts


def evaluate(point: StudyPoint) -> dict[str, Any]:
    """Solve one point from every guess, each from its own starting point on the compiled model of
    its N (:func:`compiled_point`: the same starting point as a file of its own, so a point's
    answer does not depend on which points ran before it); the best one's row (JSON-able) for the
    store."""
    spec = RcsStudySpec.model_validate_json(point.study)
    tic = time.perf_counter()
    solver, starts = compiled_point(point.study, point.obstacles)
    best: tuple[float, Result, np.ndarray] | None = None
    tried = []
    for amplitude, start in zip(spec.guesses, starts, strict=True):
        result = solver.solve(parameters={"alpha": point.alpha}, guess=start)
        tried.append({"guess": amplitude, "status": result.status.value, "objective": result.objective})
        objective, grid = result.objective, result.time
        if result.ok and objective is not None and grid is not None and (best is None or objective < best[0]):
            best = (objective, result, grid)
    row: dict[str, Any] = {
        "obstacles": point.obstacles,
        "alpha": point.alpha,
        "sigma": spec.std,
        "attempts": tried,
        "seconds": time.perf_counter() - tic,
    }
    if best is None:
        return row | {"status": "error"}
    _, result, time_grid = best
    mc = result.metrics["monte_carlo"]
    return row | {
        "status": result.status.value,
        "t_final": result.t_final,
        "objective": result.objective,
        "rcs_cost": result.metrics["sensitivity_cost"],
        "collision_probability": mc["collision_probability"],
        "collision_probability_ci": mc["collision_probability_ci"],
        "path": {"x": list(map(float, result.states["x"])), "y": list(map(float, result.states["y"]))},
        "time": list(map(float, time_grid)),
    }


class StoredPath(BaseModel):
    """A kept path of one point: x and y along its time grid."""

    x: list[Finite]
    y: list[Finite]


class StoredRow(BaseModel):
    """A stored point of the §6.4.4 study (:func:`evaluate`'s row), as it must be to be reused."""

    model_config = ConfigDict(extra="allow")

    obstacles: int
    alpha: Finite
    status: str
    seconds: Finite
    t_final: Finite | None = None
    objective: float | None = None
    collision_probability: Finite | None = None
    path: StoredPath | None = None
    time: list[Finite] | None = None

    @model_validator(mode="after")
    def _path_on_its_grid(self) -> StoredRow:
        if self.path is not None and not (len(self.path.x) == len(self.path.y) == len(self.time or [])):
            raise ValueError("path.x, path.y and time differ in length")
        return self


class RcsStudyModel(PointStudyModel[RcsStudySpec]):
    """The §6.4.4 study ready to run (or resume) into its store."""

    row_model = StoredRow

    def points(self) -> dict[str, Any]:
        return study_points(self.spec)

    def point_function(self) -> Callable[[Any], dict[str, Any]]:
        return evaluate

    def prepare(self, store: ResultStore) -> None:
        """The store's ``study`` record: a sweep over N, α and σ whose headline is P_c (what
        ``gamespec results`` shows)."""
        meta = {"type": "sweep", "problem": self.spec.name, "parameters": list(PARAMETERS)}
        store.set_meta("study", meta | {"headline": list(HEADLINE)})

    def result(self, rows: list[dict[str, Any]], run: StudyRun) -> Result:
        solved = sum(r["status"] != "error" for r in rows)
        if solved == len(rows):
            status, message = Status.OPTIMAL, f"all {len(rows)} points solved"
        else:
            status = Status.FEASIBLE if solved else Status.ERROR
            message = f"{len(rows) - solved} of {len(rows)} points failed from every guess"
        return Result(
            status=status,
            message=message,
            arrays=arrays(rows),
            metrics={
                "table": summarize(rows),
                "points": len(rows),
                "solved": solved,
                "sigma": self.spec.std,
                "sigma_is": self.spec.sigma_is,
                "radius": self.spec.radius,
                "layout": {str(n): layout(self.spec, n) for n in self.spec.obstacles},
                "seconds": {f"N={r['obstacles']},alpha={r['alpha']:g}": r["seconds"] for r in rows},
                "computed": run.computed,
                "store": str(self.spec.store),
            },
        )


class RcsStudy(PointStudy):
    """Runs the §6.4.4 study (see module doc); each point's OCP is solved on ``ocp_backend``."""

    name: ClassVar[str] = "rcs_study"
    kinds: ClassVar[frozenset[str]] = frozenset({"rcs_multi_obstacle_study"})
    model: ClassVar[type[PointStudyModel[Any]]] = RcsStudyModel


def rcs_study_summary(result: Result) -> Rows:
    """:func:`~gamespec.studies.report.study_summary`, then one row per point of
    ``metrics.table``: ``N = n, α = a, σ = s`` → P_c [interval], objective, t_f, status."""
    rows: Rows = list(study_summary(result))
    for entry in result.metrics.get("table", []):
        key = f"N = {entry['obstacles']}, α = {entry['alpha']:g}, σ = {entry.get('sigma', float('nan')):g}"
        rows.append((key, point_line(entry)))
    return rows
