"""What the study kinds of independent points share (the Table 2.1 study, the §6.4.4 trade-off):
a compiled model that runs every point of the spec's grid through
:func:`~gamespec.studies.runner.run_study` into the spec's store, on the executor its options name,
and turns the rows into one Result. A subclass gives the points, the per-point function (a
module-level function, so that process and Dask workers can import it) and the Result."""

from __future__ import annotations

import time
from abc import abstractmethod
from collections.abc import Callable, Mapping
from typing import Any, ClassVar, Generic, TypeVar, cast

from pydantic import BaseModel, Field, ValidationError

from gamespec.compiling import Availability, CompiledModel, Inputs, refuse_inputs, validated_options
from gamespec.errors import SpecError, UnsupportedFeature
from gamespec.result import Result
from gamespec.solving import get_backend
from gamespec.specs.base import SpecBase, StrictModel, StudySpecBase
from gamespec.specs.hashing import spec_hash
from gamespec.studies.executors import SCHEDULER_ENV, executor
from gamespec.studies.runner import StudyRun, run_study
from gamespec.studies.store import ResultStore

USER_CHOICES = ("scheduler", "insecure_scheduler")
"""Where a study runs: chosen by the user (``--scheduler``, ``GAMESPEC_SCHEDULER``, the API's
``options``), never by a problem file."""

SCHEDULER_FROM_FILE = (
    "a problem file cannot choose the Dask scheduler its study runs on: a scheduler can run code in "
    "the process that solves the file; pass --scheduler ADDRESS (or set GAMESPEC_SCHEDULER) instead"
)


class StudyOptions(StrictModel):
    """Options of the point studies (``solver.options.study``, ``solver.options.rcs_study``)
    that a problem file may give; the scheduler is not one of them (:data:`USER_CHOICES`)."""

    workers: int = Field(1, ge=1, description="Worker processes (1: everything in this process).")
    executor: str | None = Field(
        None,
        description="Executor plugin: serial, process or dask (default: serial for one worker, "
        "process for more, dask when a scheduler is given).",
    )
    progress: bool = Field(
        False,
        description="Show a progress bar on stderr (`gamespec pursuit study` does; `gamespec solve` "
        "shows its own spinner instead).",
    )


class StudyRunOptions(StudyOptions):
    """:class:`StudyOptions` with where the study runs, as the user chose it (never from a file)."""

    scheduler: str | None = Field(
        None, description=f"Address of a running Dask scheduler (default: ${SCHEDULER_ENV})."
    )
    insecure_scheduler: bool = Field(
        False, description="Reach a scheduler on another machine without verified TLS (README, Security)."
    )


StudySpecT = TypeVar("StudySpecT", bound=StudySpecBase)


class PointStudyModel(CompiledModel, Generic[StudySpecT]):
    """A study of a ``StudySpecT`` spec ready to run (or resume) into its store."""

    def __init__(self, spec: StudySpecT, options: StudyRunOptions) -> None:
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

    row_model: ClassVar[type[BaseModel]]
    """What a stored row must be to be reused (a store is untrusted input): one that does not
    validate is computed again."""

    def reusable(self, row: Any) -> bool:
        """Whether a stored row validates as :attr:`row_model`."""
        try:
            self.row_model.model_validate(row)
        except ValidationError:
            return False
        return True

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
            executor=executor(
                options.executor, options.workers, options.scheduler, insecure=options.insecure_scheduler
            ),
            description=self.spec.name,
            show_progress=options.progress,
            accept=self.reusable,
            spec_hash=spec_hash(self.spec),
        )
        result = self.result([run.values[key] for key in points], run)
        message = f"{result.message} ({run.computed} computed now, {run.reused} read from {self.spec.store})"
        return result.model_copy(update={"message": message, "solve_time_s": time.perf_counter() - tic})


class PointStudy:
    """A :class:`~gamespec.compiling.study_protocol.Study` of independent points: checks that the
    file's ``ocp_backend`` is there, then builds :attr:`model`."""

    name: ClassVar[str]
    kinds: ClassVar[frozenset[str]]
    features: ClassVar[frozenset[str]] = frozenset()
    options_model: ClassVar[type[StrictModel]] = StudyOptions
    model: ClassVar[type[PointStudyModel[Any]]]

    @classmethod
    def available(cls) -> Availability:
        """Always: a point study needs only gamespec (its points' backend is checked at compile)."""
        return Availability(True, "needs nothing beyond gamespec's dependencies")

    @classmethod
    def validate_options(cls, raw: Mapping[str, Any], source: str = "<spec>") -> StrictModel:
        """The file's block, refused with :data:`SCHEDULER_FROM_FILE` when it names a scheduler."""
        for name in USER_CHOICES:
            if name in raw:
                raise SpecError(SCHEDULER_FROM_FILE, field=f"solver.options.{cls.name}.{name}", source=source)
        return validated_options(cls.options_model, cls.name, raw, source)

    def options(self, spec: SpecBase, overrides: dict[str, Any] | None = None) -> StudyRunOptions:
        """The file's options (:meth:`validate_options`) with the caller's ``overrides``, which
        alone may say where the study runs (``scheduler``, ``insecure_scheduler``)."""
        chosen = dict(overrides or {})
        where = {name: chosen.pop(name) for name in USER_CHOICES if name in chosen}
        given = self.validate_options({**spec.solver.options.get(self.name, {}), **chosen}, spec.source)
        try:
            return StudyRunOptions.model_validate(given.model_dump() | where)
        except ValidationError as err:
            raise SpecError(_first_error(err), field="options", source=spec.source) from None

    def compile(self, spec: SpecBase, options: StrictModel) -> PointStudyModel[Any]:
        """The study of ``spec`` ready to run; UnsupportedFeature for a kind it does not run."""
        if spec.kind not in self.kinds:
            raise UnsupportedFeature(f"study {self.name!r} does not run kind {spec.kind!r}")
        study = cast(StudySpecBase, spec)
        get_backend(study.ocp_backend)
        return self.model(study, cast(StudyRunOptions, options))


def _first_error(err: ValidationError) -> str:
    first = err.errors()[0]
    return f"{'.'.join(map(str, first['loc']))}: {first['msg']}"
