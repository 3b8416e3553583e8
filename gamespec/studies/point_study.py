"""What the study kinds of independent points share (the Table 2.1 study, the §6.4.4 trade-off):
a compiled model that runs every point of the spec's grid through
:func:`~gamespec.studies.runner.run_study` into the spec's store, on the executor its options name,
and turns the rows into one Result. A subclass gives the points, the per-point function (a
module-level function, so that process and Dask workers can import it) and the Result."""

from __future__ import annotations

import time
from abc import abstractmethod
from collections.abc import Callable
from typing import Any, ClassVar

from pydantic import Field

from gamespec.backend import Backend, CompiledModel, Inputs, refuse_inputs
from gamespec.errors import UnsupportedFeature
from gamespec.loader import spec_hash
from gamespec.result import Result
from gamespec.solving import get_backend
from gamespec.specs.base import SpecBase, StrictModel
from gamespec.studies.executors import SCHEDULER_ENV, executor
from gamespec.studies.runner import StudyRun, run_study
from gamespec.studies.store import ResultStore


class StudyOptions(StrictModel):
    """Options of the point-study backends (``solver.options.study``, ``solver.options.rcs_study``)."""

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


class PointStudyModel(CompiledModel):
    """A study ready to run (or resume) into its store; ``options`` has ``executor``, ``workers``,
    ``scheduler`` and ``progress``."""

    def __init__(self, spec: SpecBase, options: StrictModel) -> None:
        self.spec = spec
        self.options = options

    @abstractmethod
    def points(self) -> dict[str, Any]:
        """The study's points by key."""

    @abstractmethod
    def point_function(self) -> Callable[[Any], dict[str, Any]]:
        """The function that solves one point into its (JSON-able) row."""

    @abstractmethod
    def result(self, rows: list[dict[str, Any]], run: StudyRun) -> Result:
        """The Result of all rows (in the order of :meth:`points`)."""

    def prepare(self, store: ResultStore) -> None:
        """Record what the store holds before the run (nothing by default)."""

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        refuse_inputs(inputs, self.spec.kind)
        if parameters:
            raise UnsupportedFeature(f"a {self.spec.kind} takes no runtime parameters: --set its fields")
        tic = time.perf_counter()
        points = self.points()
        store = ResultStore(self.spec.store)
        self.prepare(store)
        options = self.options
        run = run_study(
            points,
            self.point_function(),
            store,
            executor=executor(options.executor, options.workers, options.scheduler),
            description=self.spec.name,
            show_progress=options.progress,
            spec_hash=spec_hash(self.spec),
        )
        result = self.result([run.values[key] for key in points], run)
        message = f"{result.message} ({run.computed} computed now, {run.reused} read from {self.spec.store})"
        return result.model_copy(update={"message": message, "solve_time_s": time.perf_counter() - tic})


class PointStudyBackend(Backend):
    """A backend that runs a point study: checks that its ``ocp_backend`` is there, then builds
    :attr:`model`."""

    options_model: ClassVar[type[StrictModel]] = StudyOptions
    model: ClassVar[type[PointStudyModel]]

    def _compile(self, spec: SpecBase, options: StudyOptions) -> PointStudyModel:
        get_backend(spec.ocp_backend)
        return self.model(spec, options)
