"""The ``transforms:`` section every problem file may have: requested transforms, checked at load.

Each entry is ``{<transform name>: {<options>}}``. The name is looked up lazily in the
``gamespec.transforms`` entry-point group (an unknown one is refused with the nearest name), the
transform must be a requested one of the spec's kind, and its options are validated by its
``options_model`` (and against the problem by the model's ``check_against(parameters, running,
field)`` where it has one: expressions of the parameters at their values); a bad option names its
dotted field, ``transforms.<i>.<name>.<key>``.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any, Protocol, runtime_checkable

from pydantic import ValidationError

from gamespec import registry
from gamespec.errors import SpecError

if TYPE_CHECKING:
    from gamespec.specs.base import SpecBase, StrictModel

GROUP = "gamespec.transforms"


@runtime_checkable
class ChecksAgainstProblem(Protocol):
    """Options that are checked against the problem at load (expressions of its parameters)."""

    def check_against(self, parameters: Mapping[str, float], running: Iterable[str], field: str) -> None:
        """A SpecError at ``field`` when the options do not fit the problem."""


class _ProblemSection(Protocol):
    @property
    def states(self) -> Mapping[str, Any]: ...

    @property
    def controls(self) -> Mapping[str, Any]: ...

    def parameter_values(self) -> dict[str, float]: ...


@runtime_checkable
class _WithProblem(Protocol):
    @property
    def problem(self) -> _ProblemSection: ...


def transform_class(name: str, field: str = "transforms") -> Any:
    """The transform registered as ``name``; a SpecError at ``field`` with the nearest name else.
    (A :class:`~gamespec.transforms.base.Transform` subclass: this layer, below the transforms,
    reads its ``requested``, ``source_kind``, ``target_kind`` and ``options_model`` untyped.)"""
    known = registry.names(GROUP)
    if name not in known:
        near = difflib.get_close_matches(name, known, n=1)
        hint = f"; did you mean {near[0]!r}?" if near else f" (known: {', '.join(known) or 'none'})"
        raise SpecError(f"unknown transform {name!r}{hint}", field=field)
    return registry.load(GROUP, name)


def entry(item: dict[str, dict[str, Any]], index: int) -> tuple[str, dict[str, Any]]:
    """The one ``(name, options)`` pair of entry ``index`` of the section."""
    if len(item) != 1:
        raise SpecError(
            f"each entry names one transform, as {{name: {{options}}}}; got {len(item)} keys",
            field=f"transforms.{index}",
        )
    ((name, options),) = item.items()
    return name, options or {}


def validated_options(cls: Any, name: str, options: dict[str, Any], index: int) -> StrictModel:
    """``options`` validated by the transform's ``options_model``."""
    model: type[StrictModel] = cls.options_model
    try:
        return model.model_validate(options)
    except ValidationError as err:
        errors = err.errors()
        first = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
        loc = ".".join(str(p) for p in first["loc"])
        reason = first["msg"].removeprefix("Value error, ")
        if first["type"] == "missing":
            reason = "required option is missing"
        elif first["type"] == "extra_forbidden":
            keys = list(model.model_fields)
            near = difflib.get_close_matches(str(first["loc"][-1]), keys, n=1)
            reason = f"unknown option {first['loc'][-1]!r}" + (
                f"; did you mean {near[0]!r}?" if near else f" (valid: {', '.join(keys) or 'none'})"
            )
        raise SpecError(reason, field=f"transforms.{index}.{name}" + (f".{loc}" if loc else "")) from None


def check_requested(spec: SpecBase) -> None:
    """Every entry of ``spec.transforms`` names a requested transform of ``spec.kind`` with valid
    options (see module doc); a SpecError naming the entry otherwise."""
    for index, item in enumerate(spec.transforms):
        name, options = entry(item, index)
        cls = transform_class(name, field=f"transforms.{index}")
        if not cls.requested:
            raise SpecError(
                f"transform {name!r} lowers {cls.source_kind!r} to {cls.target_kind!r} and is found "
                "by kind; it cannot be requested",
                field=f"transforms.{index}",
            )
        if cls.source_kind != spec.kind:
            raise SpecError(
                f"transform {name!r} takes kind {cls.source_kind!r}, not {spec.kind!r}",
                field=f"transforms.{index}",
            )
        checked = validated_options(cls, name, options, index)
        if isinstance(checked, ChecksAgainstProblem) and isinstance(spec, _WithProblem):
            p = spec.problem
            running = [*p.states, *p.controls, "t"]
            checked.check_against(p.parameter_values(), running, f"transforms.{index}.{name}")
