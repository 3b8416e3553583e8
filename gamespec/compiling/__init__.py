"""The backend contract (after cvxpy's solver interfaces and Pyomo's ``available()``).

A backend declares the kinds and features it supports, says whether it can run here and why not,
validates its own options block, compiles a spec once into a :class:`CompiledModel` and re-solves
that model with new parameter values, grid inputs and warm starts.

:class:`Backend` is generic in the spec class it compiles and the options model it validates
(``Backend[OptimalControlSpec, CasadiOptions]``), so a plugin's ``_compile`` is typed with its own
spec and options and mypy checks it against the contract (no narrowing of ``SpecBase``).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, Generic, TypeVar, cast

from pydantic import ValidationError

from gamespec.errors import SpecError, UnsupportedFeature
from gamespec.result import Result
from gamespec.specs.base import SpecBase, SpecT, StrictModel


@dataclass(frozen=True)
class Availability:
    """Whether a backend can run here; ``reason`` says why not (or what it found)."""

    ok: bool
    reason: str = ""


class NoOptions(StrictModel):
    """Options block of a backend that takes none."""


OptionsT = TypeVar("OptionsT", bound=StrictModel)
"""The options model a backend validates its ``solver.options.<name>`` block into."""


Inputs = Mapping[str, Any] | None
"""Grid input values by name (see :mod:`gamespec.ocp.inputs`), or None for the spec's defaults."""


class CompiledModel(ABC):
    """A spec compiled into a backend's own modelling objects, re-solvable without a rebuild."""

    build_time_s: float = 0.0

    @abstractmethod
    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        """Solve with optional new parameter values, an optional previous Result as a guess, and new
        values of grid inputs (``{name: values}``, one value per evaluation point, for kinds that
        declare inputs; see :mod:`gamespec.ocp.inputs`)."""


def refuse_inputs(inputs: Inputs, kind: str) -> None:
    """A SpecError naming the inputs when a model of ``kind``, which declares none, is given some."""
    if inputs:
        raise SpecError(
            f"kind {kind!r} takes no grid inputs, got {', '.join(sorted(inputs))}", field="inputs"
        )


ModelT = TypeVar("ModelT", bound=StrictModel)


def validated_options(
    model: type[ModelT], name: str, raw: Mapping[str, Any], source: str = "<spec>"
) -> ModelT:
    """The block ``solver.options.<name>`` validated into ``model``; a SpecError naming the file, the
    field ``solver.options.<name>.<key>`` and the reason (the nearest valid key for a misspelled one)."""
    from gamespec.loader import format_validation_error

    try:
        return model.model_validate(dict(raw))
    except ValidationError as err:
        found = format_validation_error(err, model, source, raw)
        field = ".".join(p for p in ("solver.options", name, found.field) if p)
        raise SpecError(found.reason, field=field, source=source) from None


class Backend(ABC, Generic[SpecT, OptionsT]):
    """A solver backend plugin, registered in the ``gamespec.backends`` entry-point group, that
    compiles specs of class ``SpecT`` (those of its ``kinds``) with options of class ``OptionsT``
    (its ``options_model``)."""

    name: ClassVar[str]
    kinds: ClassVar[frozenset[str]]
    features: ClassVar[frozenset[str]] = frozenset()
    options_model: type[OptionsT] = cast("type[OptionsT]", NoOptions)
    """The model of this backend's options block; a backend that takes options sets it to the class
    it is parameterized with (mypy checks that), one that takes none keeps :class:`NoOptions`."""

    @classmethod
    def available(cls) -> Availability:
        """Whether the backend's libraries import here, with the reason when they do not (a backend
        that needs nothing beyond gamespec's own dependencies keeps this default)."""
        return Availability(True, "needs nothing beyond gamespec's dependencies")

    def unsupported(self, spec: SpecBase) -> str | None:
        """Why this backend cannot take ``spec``, or None when it can."""
        if spec.kind not in self.kinds:
            return f"backend {self.name!r} does not solve kind {spec.kind!r}"
        missing = spec.required_features() - self.features
        if missing:
            return f"backend {self.name!r} lacks {', '.join(sorted(missing))}"
        return None

    def options(self, spec: SpecBase, overrides: dict[str, Any] | None = None) -> OptionsT:
        """This backend's options block from the spec's ``solver.options``, validated."""
        raw = {**self.shared_options(spec), **spec.solver.options.get(self.name, {}), **(overrides or {})}
        return self.validate_options(raw, spec.source)

    @classmethod
    def validate_options(cls, raw: Mapping[str, Any], source: str = "<spec>") -> OptionsT:
        """``raw`` validated into :attr:`options_model` (:func:`validated_options`)."""
        return validated_options(cls.options_model, cls.name, raw, source)

    def shared_options(self, spec: SpecBase) -> dict[str, Any]:
        """Option values that blocks other than this backend's own give it (none by default; the
        collocation backends take ``solver.options.nlp``); the backend's own block wins."""
        return {}

    def compile(self, spec: SpecBase, options: OptionsT | None = None) -> CompiledModel:
        """Check support, then build the backend model once. A spec of one of :attr:`kinds` is of
        class ``SpecT`` (the registry maps a kind to one spec class, the one the backend is
        parameterized with), which is what lets the checked ``spec`` through to :meth:`_compile`."""
        reason = self.unsupported(spec)
        if reason:
            raise UnsupportedFeature(reason)
        return self._compile(cast(SpecT, spec), options if options is not None else self.options(spec))

    @abstractmethod
    def _compile(self, spec: SpecT, options: OptionsT) -> CompiledModel:
        """Build the backend model (called after the support check)."""
