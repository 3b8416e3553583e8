"""Every field a user can write has a description: each kind's JSON Schema (``gamespec schema
KIND``, top level and every definition it refers to), each transform's options and each backend's
options block. Generic over the registry, so a kind, transform, backend or field added later is
covered."""

from __future__ import annotations

from typing import Any

import pytest

from gamespec import registry
from gamespec.specs.schema import json_schema


def undescribed(schema: dict[str, Any]) -> list[str]:
    """``Model.field`` for each property of the schema's objects (the top level, then each of its
    ``$defs``) without a non-empty description: its own, or, for a bare reference, that of the
    definition it refers to (pydantic leaves out a field's description equal to its model's)."""
    defs = schema.get("$defs", {})

    def described(prop: dict[str, Any]) -> bool:
        referred = defs.get(prop.get("$ref", "").rsplit("/", 1)[-1], {})
        return bool(str(prop.get("description") or referred.get("description") or "").strip())

    models = {schema.get("title", "<top>"): schema, **defs}
    return [
        f"{model}.{name}"
        for model, definition in models.items()
        for name, prop in definition.get("properties", {}).items()
        if not described(prop)
    ]


@pytest.mark.parametrize("kind", registry.names("gamespec.kinds"))
def test_every_field_of_each_kind_has_a_description(kind: str) -> None:
    assert not undescribed(json_schema(kind)), kind


@pytest.mark.parametrize("name", registry.names("gamespec.transforms"))
def test_every_transform_option_has_a_description(name: str) -> None:
    options = registry.load("gamespec.transforms", name).options_model
    assert not undescribed(options.model_json_schema()), name


@pytest.mark.parametrize("name", registry.runner_names())
def test_every_backend_option_has_a_description(name: str) -> None:
    options = registry.runner_class(name).options_model
    assert not undescribed(options.model_json_schema()), name


def test_an_undescribed_field_is_found() -> None:
    """The check itself: a field without a description, in a definition, is named."""
    schema = {
        "title": "Top",
        "properties": {
            "a": {"description": "A."},
            "b": {"$ref": "#/$defs/Inner"},
            "e": {"$ref": "#/$defs/Described"},
        },
        "$defs": {
            "Inner": {"properties": {"c": {"type": "number"}, "d": {"description": " "}}},
            "Described": {"description": "E.", "properties": {}},
        },
    }
    assert undescribed(schema) == ["Top.b", "Inner.c", "Inner.d"]
