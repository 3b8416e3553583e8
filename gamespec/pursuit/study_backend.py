"""The ``study`` backend: runs a ``pursuit_suboptimal_study`` (Table 2.1, §2.4.4) point by point.

Every point of :func:`gamespec.pursuit.study.study_points` goes through
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

import time
from typing import ClassVar

import numpy as np
from pydantic import Field

from gamespec.backend import Backend, CompiledModel, Inputs, refuse_inputs
from gamespec.errors import UnsupportedFeature
from gamespec.loader import spec_hash
from gamespec.pursuit import study
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel
from gamespec.specs.suboptimal_study import SuboptimalStudySpec
from gamespec.studies.executors import SCHEDULER_ENV, executor
from gamespec.studies.runner import run_study
from gamespec.studies.store import ResultStore

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


class StudyOptions(StrictModel):
    """Options of the ``study`` backend (``solver.options.study``)."""

    workers: int = Field(1, ge=1, description="Worker processes (1: everything in this process).")
    executor: str | None = Field(
        None,
        description="Executor plugin: serial, process or dask (default: serial for one worker, "
        "process for more, dask when a scheduler is given).",
    )
    scheduler: str | None = Field(
        None, description=f"Address of a running Dask scheduler (default: ${SCHEDULER_ENV})."
    )
    progress: bool = Field(
        False,
        description="Show a progress bar on stderr (`gamespec pursuit study` does; `gamespec solve` "
        "shows its own spinner instead).",
    )


class StudyModel(CompiledModel):
    """A study ready to run (or resume) into its store."""

    def __init__(self, spec: SuboptimalStudySpec, options: StudyOptions) -> None:
        self.spec = spec
        self.options = options

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        refuse_inputs(inputs, self.spec.kind)
        if parameters:
            raise UnsupportedFeature("a pursuit_suboptimal_study takes no parameters; edit the file")
        tic = time.perf_counter()
        points = study.study_points(self.spec)
        store = ResultStore(self.spec.store)
        store.set_meta("study", {"type": "sweep", "problem": self.spec.name, "parameters": list(SWEPT)})
        run = run_study(
            points,
            study.evaluate,
            store,
            executor=executor(self.options.executor, self.options.workers, self.options.scheduler),
            description=self.spec.name,
            show_progress=self.options.progress,
            spec_hash=spec_hash(self.spec),
        )
        rows = [run.values[key] for key in points]
        solved = [r for r in rows if "variation_percent" in r]
        status, message = _outcome(len(rows), len(solved))
        computed = run.computed
        return Result(
            status=status,
            message=f"{message} ({computed} computed now, {run.reused} read from {self.spec.store})",
            solve_time_s=time.perf_counter() - tic,
            arrays={name: np.array([r.get(name, np.nan) for r in rows]) for name in POINT_ARRAYS},
            checks={name: max((r[key] for r in solved), default=None) for name, key in POINT_CHECKS.items()},
            metrics={
                "table": study.summarize(rows),
                "points": len(rows),
                "solved": len(solved),
                "computed": computed,
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
            f"(no optimum with a defect below {study.DEFECT_TOL:g})"
        )
    return Status.ERROR, f"none of the {points} points solved"


class StudyBackend(Backend):
    """Runs the Table 2.1 study (see module doc); each point's OCP is solved on ``ocp_backend``."""

    name: ClassVar[str] = "study"
    kinds: ClassVar[frozenset[str]] = frozenset({"pursuit_suboptimal_study"})
    options_model: ClassVar[type[StrictModel]] = StudyOptions

    def _compile(self, spec: SuboptimalStudySpec, options: StudyOptions) -> StudyModel:
        from gamespec.solving import get_backend

        get_backend(spec.ocp_backend)
        return StudyModel(spec, options)
