"""Problem files (YAML, TOML, JSON) → validated spec, with ``--set`` overrides (DESIGN.md, stage 1).

YAML is read with ``yaml.safe_load`` only. Validation errors become one
:class:`~gamespec.errors.SpecError` that names the file, the dotted field and the reason, and for a
misspelled key the nearest valid one.
"""

from __future__ import annotations

import difflib
import hashlib
import json
import re
import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from gamespec import registry
from gamespec.errors import SpecError
from gamespec.specs.base import SpecBase

SUFFIXES = {".yaml": "yaml", ".yml": "yaml", ".toml": "toml", ".json": "json"}


def read_file(path: str | Path) -> dict[str, Any]:
    """The raw mapping in a problem file; a SpecError for a missing, unreadable or malformed file."""
    path = Path(path)
    fmt = SUFFIXES.get(path.suffix.lower())
    if fmt is None:
        raise SpecError(f"unknown file type {path.suffix!r} (use .yaml, .toml or .json)", source=str(path))
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SpecError("file not found", source=str(path)) from None
    except OSError as err:
        raise SpecError(f"cannot read file: {err.strerror}", source=str(path)) from None
    try:
        if fmt == "yaml":
            data = yaml.safe_load(text)
        elif fmt == "toml":
            data = tomllib.loads(text)
        else:
            data = json.loads(text)
    except (yaml.YAMLError, tomllib.TOMLDecodeError, json.JSONDecodeError) as err:
        reason = " ".join(str(err).split())
        raise SpecError(f"malformed {fmt.upper()}: {reason}", source=str(path)) from None
    if not isinstance(data, dict):
        raise SpecError("the file must hold a mapping at the top level", source=str(path))
    return data


def override_path(key: str, source: str = "--set") -> list[str]:
    """``a.b.1.c`` or ``a.b[1].c`` → ``["a", "b", "1", "c"]`` (list entries by their index)."""
    parts = re.sub(r"\[(\d+)\]", r".\1", key.strip()).split(".")
    if not all(parts):
        raise SpecError(f"cannot read the dotted path {key!r}", source=source)
    return parts


def parse_override(assignment: str) -> tuple[list[str], Any]:
    """``a.b.c=value`` → (["a", "b", "c"], value), the value read as a YAML scalar or list."""
    key, sep, value = assignment.partition("=")
    if not sep or not key.strip():
        raise SpecError(f"--set expects dotted.path=value, got {assignment!r}", source="--set")
    try:
        parsed = yaml.safe_load(value) if value.strip() else ""
    except yaml.YAMLError:
        parsed = value
    return override_path(key), parsed


def set_path(data: dict[str, Any], path: list[str], value: Any, *, create: bool, source: str) -> None:
    """Set ``data`` at ``path`` in place: mapping keys by name (missing ones made when ``create``),
    list entries by an index they already have; a SpecError naming the path otherwise."""
    node: Any = data
    for i, part in enumerate(path):
        last = i == len(path) - 1
        if isinstance(node, list):
            if not part.isdigit() or int(part) >= len(node):
                raise SpecError(
                    f"cannot set {'.'.join(path)}: {'.'.join(path[:i])} has entries 0 to {len(node) - 1}, "
                    f"not {part!r}",
                    source=source,
                )
            part = int(part)
        elif not isinstance(node, dict):
            raise SpecError(
                f"cannot set {'.'.join(path)}: {'.'.join(path[:i])} is not a mapping or a list", source=source
            )
        elif not create and part not in node:
            raise SpecError(f"cannot set {'.'.join(path)}: no field {'.'.join(path[: i + 1])}", source=source)
        if last:
            node[part] = value
            return
        if isinstance(node, dict) and node.get(part) is None:
            node[part] = {}
        node = node[part]


def apply_overrides(data: dict[str, Any], assignments: Iterable[str]) -> dict[str, Any]:
    """A copy of ``data`` with each ``dotted.path=value`` assignment applied."""
    data = json.loads(json.dumps(data))
    for assignment in assignments:
        path, value = parse_override(assignment)
        set_path(data, path, value, create=True, source="--set")
    return data


def with_values(spec: SpecBase, values: Mapping[str, Any]) -> SpecBase:
    """``spec`` with each runtime parameter or dotted field in ``values`` set, validated as at load
    (the code path of ``--set``); an unknown name is a SpecError naming it and the nearest one."""
    data = spec.model_dump(mode="json")
    for name, value in values.items():
        path = override_path(spec.parameter_path(name), source=spec.source)
        try:
            set_path(data, path, value, create=False, source=spec.source)
        except SpecError:
            known = list(spec.runtime_parameters())
            near = difflib.get_close_matches(name, known, n=1)
            hint = f"; did you mean {near[0]!r}?" if near else f" (runtime parameters: {', '.join(known)})"
            raise SpecError(
                f"unknown parameter {name!r}: no such field{hint}", field=name, source=spec.source
            ) from None
    return spec_from_dict(data, source=spec.source).with_source(spec.source, spec.file_hash)


def _valid_keys(model: type[BaseModel] | None, loc: tuple[Any, ...]) -> list[str]:
    """The field names allowed at ``loc`` (walking nested models and dicts), for suggestions."""
    parts = list(loc)
    while parts and model is not None:
        field = model.model_fields.get(str(parts.pop(0)))
        if field is None:
            return []
        annotation = field.annotation
        if getattr(annotation, "__origin__", None) is dict and parts:
            parts.pop(0)
        model = _model_in(annotation)
    return list(model.model_fields) if model is not None and not parts else []


def _model_in(annotation: Any) -> type[BaseModel] | None:
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in getattr(annotation, "__args__", ()):
        found = _model_in(arg)
        if found is not None:
            return found
    return None


_TYPE_TAGS = frozenset({"float", "int", "str", "bool", "list", "dict", "tuple", "none", "literal"})


def _is_type_tag(part: object) -> bool:
    """Pydantic adds the member of a union it tried to an error's location (``float``,
    ``constrained-float``, ``list[float]``, ``function-after[...]``); users wrote none of those."""
    return isinstance(part, str) and ("[" in part or "-" in part or part in _TYPE_TAGS)


def format_validation_error(err: ValidationError, model: type[BaseModel], source: str) -> SpecError:
    """The first pydantic error as a SpecError with dotted location and a nearest-key hint."""
    first = err.errors()[0]
    loc = tuple(p for p in first["loc"] if not _is_type_tag(p))
    field = ".".join(str(p) for p in loc)
    reason = first["msg"]
    if first["type"] == "extra_forbidden":
        keys = _valid_keys(model, loc[:-1])
        near = difflib.get_close_matches(str(loc[-1]), keys, n=1)
        reason = f"unknown key {loc[-1]!r}" + (f"; did you mean {near[0]!r}?" if near else "")
        if keys and not near:
            reason += f" (valid: {', '.join(keys)})"
    elif first["type"] == "missing":
        reason = "required field is missing"
    elif reason.startswith("Value error, "):
        reason = reason.removeprefix("Value error, ")
    if len(err.errors()) > 1:
        reason += f" (and {len(err.errors()) - 1} more error(s))"
    return SpecError(reason, field=field, source=source)


def spec_from_dict(data: Mapping[str, Any], source: str = "<spec>") -> SpecBase:
    """Validate a raw mapping into the spec class registered for its ``kind``."""
    kind = data.get("kind")
    if not isinstance(kind, str):
        known = ", ".join(registry.names("gamespec.kinds"))
        raise SpecError(f"missing or invalid 'kind' (one of: {known})", field="kind", source=source)
    try:
        cls = registry.spec_class(kind)
    except SpecError as err:
        raise SpecError(err.reason, field="kind", source=source) from None
    try:
        return cls.model_validate(dict(data))
    except ValidationError as err:
        raise format_validation_error(err, cls, source) from None
    except SpecError as err:
        raise SpecError(err.reason, field=err.field, source=source) from None


def spec_hash(spec: SpecBase) -> str:
    """A stable hash of a spec's content (provenance of Results)."""
    text = json.dumps(spec.model_dump(mode="json"), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def load(path: str | Path, overrides: Iterable[str] = ()) -> SpecBase:
    """Read, override and validate a problem file into its spec."""
    data = apply_overrides(read_file(path), overrides)
    spec = spec_from_dict(data, source=str(path))
    return spec.with_source(str(path), hashlib.sha256(Path(path).read_bytes()).hexdigest()[:16])
