"""Problem files (YAML, TOML, JSON) → validated spec, with ``--set`` overrides (DESIGN.md, stage 1).

Files are read by :func:`gamespec.reading.read_file` (within :mod:`gamespec.limits`). Validation errors
become one :class:`~gamespec.errors.SpecError` that names the file, the dotted field and the reason, and for a
misspelled key the nearest valid one.
"""

from __future__ import annotations

import difflib
import hashlib
import json
import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from gamespec import registry
from gamespec.errors import SpecError
from gamespec.reading import read_file, read_value
from gamespec.specs.base import NLP_OPTIONS, SpecBase, SpecT
from gamespec.specs.tables import FOLDER


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
    return override_path(key), read_value(value) if value.strip() else ""


def set_path(data: dict[str, Any], path: list[str], value: Any, *, create: bool, source: str) -> None:
    """Set ``data`` at ``path`` in place: mapping keys by name (missing ones made when ``create``),
    list entries by an index they already have; a SpecError naming the path otherwise."""
    node: Any = data
    for i, part in enumerate(path):
        last = i == len(path) - 1
        key: str | int = part
        if isinstance(node, list):
            if not part.isdigit() or int(part) >= len(node):
                raise SpecError(
                    f"cannot set {'.'.join(path)}: {'.'.join(path[:i])} has entries 0 to {len(node) - 1}, "
                    f"not {part!r}",
                    source=source,
                )
            key = int(part)
        elif not isinstance(node, dict):
            raise SpecError(
                f"cannot set {'.'.join(path)}: {'.'.join(path[:i])} is not a mapping or a list", source=source
            )
        elif not create and part not in node:
            raise SpecError(f"cannot set {'.'.join(path)}: no field {'.'.join(path[: i + 1])}", source=source)
        if last:
            node[key] = value
            return
        if isinstance(node, dict) and node.get(key) is None:
            node[key] = {}
        node = node[key]


def apply_overrides(data: dict[str, Any], assignments: Iterable[str]) -> dict[str, Any]:
    """A copy of ``data`` with each ``dotted.path=value`` assignment applied."""
    data = json.loads(json.dumps(data))
    for assignment in assignments:
        path, value = parse_override(assignment)
        set_path(data, path, value, create=True, source="--set")
    return data


def with_values(spec: SpecT, values: Mapping[str, Any]) -> SpecT:
    """``spec`` with each runtime parameter or dotted field in ``values`` set, validated as at load
    (the code path of ``--set``), of ``spec``'s class; an unknown name is a SpecError naming it and
    the nearest one."""
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
    new = spec_from_dict(data, source=spec.source).with_source(spec.source, spec.file_hash)
    if not isinstance(new, type(spec)):
        raise SpecError(f"a value changed the kind to {new.kind!r}", field="kind", source=spec.source)
    return new


def _valid_keys(model: type[BaseModel] | None, loc: tuple[Any, ...]) -> list[str]:
    """The field names allowed at ``loc`` (walking nested models and dicts), for suggestions."""
    parts = list(loc)
    while parts and model is not None:
        field = model.model_fields.get(str(parts.pop(0)))
        if field is None:
            return []
        annotation = field.annotation
        if getattr(annotation, "__origin__", None) in (dict, list, tuple) and parts:
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


def _user_location(loc: tuple[Any, ...], data: Any) -> tuple[Any, ...]:
    """``loc`` without pydantic's union tags: a part the file holds at that point (a key such as
    ``x-notes`` or ``pursuers[1]``, a list index) is always kept; only a part the file does not hold
    and that looks like a tag is dropped."""
    kept: list[Any] = []
    node = data
    for part in loc:
        in_list = isinstance(node, list) and isinstance(part, int) and -len(node) <= part < len(node)
        if in_list or (isinstance(node, Mapping) and part in node):
            node = node[part]
        elif _is_type_tag(part):
            continue
        else:
            node = None
        kept.append(part)
    return tuple(kept)


def format_validation_error(
    err: ValidationError, model: type[BaseModel], source: str, data: Any = None
) -> SpecError:
    """The first pydantic error as a SpecError with dotted location and a nearest-key hint
    (``data``, the validated input, tells the file's own keys from pydantic's union tags)."""
    first = err.errors()[0]
    loc = _user_location(tuple(first["loc"]), data)
    field = ".".join(str(p) for p in loc)
    reason = first["msg"]
    if first["type"] == "extra_forbidden" and loc:
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
        cls: type[SpecBase] = registry.spec_class(kind)
    except SpecError as err:
        raise SpecError(err.reason, field="kind", source=source) from None
    try:
        spec = cls.model_validate(dict(data), context={FOLDER: _folder(source)})
    except ValidationError as err:
        raise format_validation_error(err, cls, source, data) from None
    except SpecError as err:
        raise SpecError(err.reason, field=err.field, source=source) from None
    check_backend_options(spec, source)
    return spec


def _folder(source: str) -> str:
    """The folder of the problem file ``source`` (where its table files lie); the working directory
    for a spec that is no file."""
    path = Path(source)
    return str(path.parent) if source != "<spec>" and path.suffix else "."


def check_backend_options(spec: SpecBase, source: str) -> None:
    """Validate every block of ``solver.options`` with its backend's options model (imported only
    when the file has a block for it), so a misspelled backend or option fails at load, not at solve.
    A backend whose module cannot be imported here is left to the solve, which says why."""
    for name, block in spec.solver.options.items():
        if name == NLP_OPTIONS:
            continue
        known = registry.runner_names()
        if name not in known:
            near = difflib.get_close_matches(name, known, n=1)
            hint = f"; did you mean {near[0]!r}?" if near else f" (known: {', '.join(known)})"
            raise SpecError(f"unknown backend {name!r}{hint}", field=f"solver.options.{name}", source=source)
        try:
            backend = registry.runner_class(name)
        except ImportError:
            continue
        backend.validate_options(block, source)


def refuse_undeclared_parameters(data: Mapping[str, Any], assignments: Iterable[str]) -> None:
    """A SpecError (with the nearest declared name) for a ``--set problem.parameters.NAME=...`` whose
    NAME the file does not declare: a misspelled parameter would otherwise be added unused and change
    nothing."""
    problem = data.get("problem")
    declared = problem.get("parameters") if isinstance(problem, Mapping) else None
    if not isinstance(declared, Mapping):
        return
    for assignment in assignments:
        path, _ = parse_override(assignment)
        if len(path) == 3 and path[:2] == ["problem", "parameters"] and path[2] not in declared:
            near = difflib.get_close_matches(path[2], [str(k) for k in declared], n=1)
            hint = f"; did you mean {near[0]!r}?" if near else f" (declared: {', '.join(map(str, declared))})"
            raise SpecError(f"unknown parameter {path[2]!r}{hint}", field=".".join(path), source="--set")


def check_overrides(data: Mapping[str, Any], assignments: Iterable[str]) -> None:
    """Each ``--set`` value read within the limits of a file (:func:`gamespec.reading.read_value`),
    and no undeclared parameter set; a SpecError from ``--set`` otherwise."""
    assignments = list(assignments)
    for assignment in assignments:
        _, sep, value = assignment.partition("=")
        if sep and value.strip():
            read_value(value)
    refuse_undeclared_parameters(data, assignments)


def load(path: str | Path, overrides: Iterable[str] = ()) -> SpecBase:
    """Read, override and validate a problem file into its spec."""
    raw = read_file(path)
    check_overrides(raw, overrides)
    data = apply_overrides(raw, overrides)
    spec = spec_from_dict(data, source=str(path))
    return spec.with_source(str(path), hashlib.sha256(Path(path).read_bytes()).hexdigest()[:16])
