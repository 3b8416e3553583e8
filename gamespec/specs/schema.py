"""JSON Schema of problem files: one kind, or the union of every registered kind by ``kind``."""

from __future__ import annotations

from typing import Annotated, Any, Union

from pydantic import Field, TypeAdapter

from gamespec import registry


def json_schema(kind: str | None = None) -> dict[str, Any]:
    """The JSON Schema of ``kind``, or of any problem file (discriminated by ``kind``)."""
    if kind is not None:
        return registry.spec_class(kind).model_json_schema()
    classes = tuple(registry.spec_class(k) for k in registry.names("gamespec.kinds"))
    if len(classes) == 1:
        return classes[0].model_json_schema()
    union = Annotated[Union[classes], Field(discriminator="kind")]  # noqa: UP007
    return TypeAdapter(union).json_schema()
