"""Base pydantic models for everything a user writes, and the sections every problem file shares.

Following SQLMesh's config layer: ``extra="forbid"`` everywhere, and errors reported with their
dotted location and the nearest valid key (see :func:`gamespec.loader.format_validation_error`).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Annotated, Any, ClassVar, Protocol, TypeVar

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, FiniteFloat, PrivateAttr, model_validator

from gamespec.limits import MAX_COORDINATE, MAX_SPEED

Number = FiniteFloat
"""A finite number: NaN and ±inf are refused at load, with the field named."""

Value = Number | str
"""A finite number, or an expression over the problem's parameters (each kind checks that the
expression evaluates to a finite number)."""

Coordinate = Annotated[Number, Field(ge=-MAX_COORDINATE, le=MAX_COORDINATE)]
"""A position coordinate, finite and within :data:`~gamespec.limits.MAX_COORDINATE`."""

Speed = Annotated[Number, Field(ge=0, le=MAX_SPEED)]
"""A player's speed, finite, non-negative and within :data:`~gamespec.limits.MAX_SPEED`."""


def _known_backend(name: str) -> str:
    from gamespec import registry

    known = registry.runner_names()
    if name not in known:
        raise ValueError(f"unknown backend {name!r} (known: {', '.join(known)})")
    return name


BackendName = Annotated[str, AfterValidator(_known_backend)]
"""The name of an installed backend or study (an entry point of ``gamespec.backends`` or
``gamespec.studies``), checked at load."""


class StrictModel(BaseModel):
    """A pydantic model that rejects unknown keys and is immutable once built."""

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)


NLP_OPTIONS = "nlp"
"""The ``solver.options`` block that is not one backend's: IPOPT options by IPOPT's names (``tol``,
``max_iter``, ``max_wall_time``, ``mu_strategy`` ...), given once for every collocation backend."""


class SolverSection(StrictModel):
    """Which backend solves the problem, and the knobs of each backend (validated by the backend).

    ``options`` maps a backend name to that backend's own options block, so the same file can be
    solved on several backends without re-typing anything; ``options.nlp`` gives NLP (IPOPT) options
    once to every collocation backend.
    """

    backend: BackendName | None = Field(None, description="Backend name; the kind's default when omitted.")
    options: dict[str, dict[str, Any]] = Field(
        default_factory=dict, description="Per-backend option blocks, keyed by backend name."
    )


class _ParametersSection(Protocol):
    @property
    def parameters(self) -> Mapping[str, float]: ...


class _WithParameters(Protocol):
    @property
    def problem(self) -> _ParametersSection: ...


class ProblemParameters:
    """Mixin of the kinds whose runtime parameters are ``problem.parameters``, addressed by their
    short names (``rho`` for ``problem.parameters.rho``) as well as by the dotted path."""

    def runtime_parameters(self: _WithParameters) -> dict[str, float]:
        return dict(self.problem.parameters)

    def parameter_path(self: _WithParameters, name: str) -> str:
        return f"problem.parameters.{name}" if name in self.problem.parameters else name


def _analyses_choice(choice: str | list[str]) -> str | list[str]:
    """``all``, ``none``, or a non-empty list of the names of declared analyses."""
    if isinstance(choice, str):
        if choice not in ("all", "none"):
            raise ValueError(f"give all, none or a list of analysis names, not {choice!r}")
        return choice
    if not choice:
        raise ValueError("give all, none or a list of analysis names, not an empty list")
    from gamespec.analyses import unknown

    reason = unknown(choice)
    if reason is not None:
        raise ValueError(reason)
    return choice


AnalysesChoice = Annotated[str | list[str], AfterValidator(_analyses_choice)]
"""Which analyses run (:mod:`gamespec.analyses`): ``all``, ``none`` or names declared by an
installed transform or kind, checked at load."""

RequestedTransforms = list[dict[str, dict[str, Any]]]
"""The ``transforms:`` section: ``[{<transform name>: {<options>}}, ...]``, applied in order."""


class SpecBase(StrictModel):
    """Fields shared by every problem kind; subclasses fix ``kind`` to a literal.

    A kind says which of its values a compiled model takes at solve time
    (:meth:`runtime_parameters`, addressed by :meth:`parameter_path`) and which fields only give a
    starting point (``guess_fields``); :meth:`structure` is everything else, what a compiled model
    was built from.
    """

    kind: str
    name: str = Field("unnamed", description="A short name used in reports and output folders.")
    description: str = Field("", description="Free text: what the file is (the docs' gallery shows it).")
    solver: SolverSection = Field(
        default_factory=SolverSection,
        description="Which backend solves the file, and each backend's own options.",
    )
    transforms: RequestedTransforms = Field(
        default_factory=list,
        description="Requested transforms, [{name: {options}}], applied in order before the solve.",
    )
    analyses: AnalysesChoice | None = Field(
        None,
        description="Which analyses of the solution run (Monte Carlo, re-simulation, LQR tracking ...): "
        "all, none, or a list of names; omitted: all (a study passes it on to its points).",
    )

    guess_fields: ClassVar[tuple[str, ...]] = ()
    _source: str = PrivateAttr("<spec>")
    _file_hash: str = PrivateAttr("")

    @property
    def default_backend(self) -> str:
        """The backend that solves this kind when a file names none (its :class:`~gamespec.registry.
        Kind`'s; empty for a study kind, which its study runs)."""
        from gamespec import registry

        return registry.kind(self.kind).default_backend or ""

    @property
    def source(self) -> str:
        """The file this spec was loaded from, or ``<spec>``."""
        return self._source

    def with_source(self, source: str, file_hash: str) -> SpecBase:
        """Record the file this spec was read from (and its hash) for reports and provenance."""
        self._source = source
        self._file_hash = file_hash
        return self

    @property
    def file_hash(self) -> str:
        """SHA-256 (first 16 hex digits) of the file this spec was loaded from, or ``""``."""
        return self._file_hash

    def required_features(self) -> frozenset[str]:
        """Features a backend must declare to take this spec (e.g. ``free_final_time``)."""
        return frozenset()

    def as_solved(self) -> SpecBase:
        """This spec with what a backend derives from it written out (``gamespec show
        --transformed`` prints it); a kind whose backends derive nothing keeps this default."""
        return self

    @property
    def objective_sense(self) -> str:
        """``minimize`` or ``maximize``: which objective is better, for comparisons; ``saddle`` for a
        game whose objective is a saddle value (neither lower nor higher is better)."""
        return "minimize"

    @model_validator(mode="after")
    def _requested_transforms(self) -> SpecBase:
        if self.transforms:
            from gamespec.specs.requested import check_requested

            check_requested(self)
        return self

    def runtime_parameters(self) -> dict[str, float]:
        """The values a compiled model of this spec takes as ``parameters=`` (none by default)."""
        return {}

    def parameter_path(self, name: str) -> str:
        """The dotted field a runtime parameter ``name`` stands for (the name itself by default)."""
        return name

    def analysis_values(self) -> dict[str, Any]:
        """The fields that only analyses read (a Monte Carlo's distributions), by dotted path: no
        transform's ``apply`` and no backend reads them, so a compiled model re-solves for new
        values of them (:meth:`gamespec.solving.Solver.mapped_steps`) and :meth:`structure` leaves
        them out (none by default)."""
        return {}

    def structure(self, with_guess: bool = False) -> dict[str, Any]:
        """This spec without its runtime parameter values, its :meth:`analysis_values`, name and
        description (and without its starting point unless ``with_guess``): two specs with the
        same structure compile to the same model."""
        data = self.model_dump(mode="json")
        data.pop("name")
        data.pop("description")
        blanked = [self.parameter_path(n) for n in self.runtime_parameters()] + list(self.analysis_values())
        for path in blanked + ([] if with_guess else list(self.guess_fields)):
            *parents, last = path.split(".")
            node: Any = data
            for part in parents:
                node = node[int(part)] if isinstance(node, list) else node[part]
            node[int(last) if isinstance(node, list) else last] = None
        return data


class StudySpecBase(SpecBase):
    """A study kind's spec (its points solved on ``ocp_backend``, saved under ``store``); each kind
    declares both fields again with its own default and description."""

    ocp_backend: BackendName
    store: Path


SpecT = TypeVar("SpecT", bound=SpecBase)
"""A spec class (a backend's, or what :func:`gamespec.loader.with_values` returns: its argument's)."""
