"""Reading a problem file (YAML, TOML, JSON) into a plain mapping, within the limits of
:mod:`gamespec.limits`.

Every way a file can be unreadable is a :class:`~gamespec.errors.SpecError` naming the file, the
field or the line and column, and the reason: missing, too large, not UTF-8, malformed, duplicate
keys, nesting too deep, too many values after YAML aliases are expanded (a "billion laughs" file is
refused, never expanded), recursive aliases, integer literals longer than Python converts, and values
that are none of mapping, list, text, number, boolean or null (YAML dates, sets, binary).

YAML is read by :class:`SafeProblemLoader`, PyYAML's ``SafeLoader`` with these checks added: it
constructs exactly what ``yaml.safe_load`` constructs (no Python objects), except that dates stay text.
"""

from __future__ import annotations

import json
import math
import re
import tomllib
from collections.abc import Hashable
from pathlib import Path
from typing import Any, ClassVar

import yaml
from yaml.composer import ComposerError

from gamespec.errors import RefusedInput, SpecError
from gamespec.limits import MAX_DEPTH, MAX_FILE_BYTES, MAX_INT_DIGITS, MAX_VALUES

SUFFIXES = {".yaml": "yaml", ".yml": "yaml", ".toml": "toml", ".json": "json"}

_MAX_INT_BITS = int(MAX_INT_DIGITS * math.log2(10))
_LONG_INTEGER = re.compile(rf"[0-9][0-9_]{{{MAX_INT_DIGITS},}}")
_TIMESTAMP = "tag:yaml.org,2002:timestamp"
_MERGE = "tag:yaml.org,2002:merge"
_FLOAT = "tag:yaml.org,2002:float"
_EXPONENT_FLOAT = re.compile(r"^[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+$")


class RefusedYAML(ComposerError):
    """Well-formed YAML that gamespec refuses: a recursive alias, nesting or alias expansion beyond
    the limits, a duplicate key."""


class SafeProblemLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses duplicate keys and recursive aliases, and bounds the nesting
    depth and the number of values the document holds once its aliases are expanded.

    The expanded size of every node is counted as it is composed (an alias counts the whole node it
    names), so nested aliases are refused at :data:`~gamespec.limits.MAX_VALUES` without expanding them.
    """

    yaml_implicit_resolvers: ClassVar[dict[str, list[tuple[str, re.Pattern[str]]]]] = {
        first: [(tag, regexp) for tag, regexp in resolvers if tag != _TIMESTAMP]
        for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
    }
    for _first in "-+0123456789":
        # YAML 1.2's floats without a dot (``1e-8``), which YAML 1.1 reads as text
        yaml_implicit_resolvers.setdefault(_first, []).insert(0, (_FLOAT, _EXPONENT_FLOAT))
    del _first

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._open_anchors: list[str | None] = []
        self._expanded: dict[int, int] = {}

    def compose_node(self, parent: yaml.Node | None, index: object) -> yaml.Node:
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            if event.anchor in self._open_anchors:
                raise RefusedYAML(None, None, f"recursive alias *{event.anchor}", event.start_mark)
            return super().compose_node(parent, index)
        if len(self._open_anchors) >= MAX_DEPTH:
            raise RefusedYAML(None, None, f"nested deeper than {MAX_DEPTH} levels", event.start_mark)
        self._open_anchors.append(getattr(event, "anchor", None))
        try:
            node = super().compose_node(parent, index)
        finally:
            self._open_anchors.pop()
        self._count(node)
        return node

    def _count(self, node: yaml.Node) -> None:
        if isinstance(node, yaml.MappingNode):
            children = [child for pair in node.value for child in pair]
        elif isinstance(node, yaml.SequenceNode):
            children = node.value
        else:
            children = []
        size = 1 + sum(self._expanded.get(id(child), 1) for child in children)
        if size > MAX_VALUES:
            raise RefusedYAML(
                None, None, f"more than {MAX_VALUES} values once aliases are expanded", node.start_mark
            )
        self._expanded[id(node)] = size

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        if isinstance(node, yaml.MappingNode):
            seen: set[Any] = set()
            for key_node, _ in node.value:
                if key_node.tag == _MERGE or not isinstance(key_node, yaml.ScalarNode):
                    continue
                key = self.construct_object(key_node)
                if not isinstance(key, Hashable):
                    continue
                if key in seen:
                    raise RefusedYAML(
                        "while constructing a mapping",
                        node.start_mark,
                        f"found duplicate key {key!r}",
                        key_node.start_mark,
                    )
                seen.add(key)
        return super().construct_mapping(node, deep=deep)


def read_file(path: str | Path) -> dict[str, Any]:
    """The raw mapping in a problem file; a SpecError for a missing, unreadable, malformed or
    oversized file."""
    path = Path(path)
    source = str(path)
    fmt = SUFFIXES.get(path.suffix.lower())
    if fmt is None:
        raise SpecError(f"unknown file type {path.suffix!r} (use .yaml, .toml or .json)", source=source)
    text = _decode(_read_bytes(path), source)
    data = _parse(text, fmt, source)
    _check_values(data, source)
    if not isinstance(data, dict):
        raise SpecError("the file must hold a mapping at the top level", source=source)
    return data


def read_value(text: str, source: str = "--set") -> Any:
    """A ``--set`` value read as YAML within the same limits as a file (the text itself when it is
    not YAML, as :func:`gamespec.loader.parse_override` reads it); a SpecError for a refused one."""
    try:
        value = _parse(text, "yaml", source)
    except RefusedInput:
        raise
    except SpecError:
        return text
    _check_values(value, source)
    return value


def _read_bytes(path: Path) -> bytes:
    try:
        with path.open("rb") as handle:
            raw = handle.read(MAX_FILE_BYTES + 1)
    except FileNotFoundError:
        raise SpecError("file not found", source=str(path)) from None
    except OSError as err:
        raise SpecError(f"cannot read file: {err.strerror or err}", source=str(path)) from None
    if len(raw) > MAX_FILE_BYTES:
        raise SpecError(f"file larger than the limit of {MAX_FILE_BYTES} bytes", source=str(path))
    return raw


def _line_column(text: str | bytes, offset: int) -> str:
    newline = "\n" if isinstance(text, str) else b"\n"
    line = text.count(newline, 0, offset) + 1
    column = offset - (text.rfind(newline, 0, offset) + 1) + 1
    return f"line {line}, column {column}"


def _decode(raw: bytes, source: str) -> str:
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        where = _line_column(raw, err.start)
        raise SpecError(f"not UTF-8 text: byte 0x{raw[err.start]:02x} at {where}", source=source) from None


def _unique_pairs(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """``object_pairs_hook`` of :func:`json.loads`: a mapping, refusing a key given twice."""
    data: dict[str, Any] = {}
    for key, value in pairs:
        if key in data:
            raise ValueError(f"duplicate key {key!r}")
        data[key] = value
    return data


def _parse(text: str, fmt: str, source: str) -> Any:
    try:
        if fmt == "yaml":
            return yaml.load(text, Loader=SafeProblemLoader)  # a SafeLoader: safe_load plus checks
        if fmt == "toml":
            return tomllib.loads(text)
        return json.loads(text, object_pairs_hook=_unique_pairs)
    except RefusedYAML as err:
        refused, reason = True, _yaml_reason(err)
    except yaml.MarkedYAMLError as err:
        refused, reason = False, _yaml_reason(err)
    except (yaml.YAMLError, tomllib.TOMLDecodeError, json.JSONDecodeError) as err:
        refused, reason = False, " ".join(str(err).split())
    except RecursionError:
        refused, reason = True, f"nested deeper than {MAX_DEPTH} levels"
    except ValueError as err:
        long_literal = _LONG_INTEGER.search(text)
        refused = "digits" in str(err) and long_literal is not None
        if refused:
            where = _line_column(text, long_literal.start())
            reason = f"integer literal longer than {MAX_INT_DIGITS} digits at {where}"
        else:
            reason = " ".join(str(err).split())
    raise (RefusedInput if refused else SpecError)(f"malformed {fmt.upper()}: {reason}", source=source)


def _yaml_reason(err: yaml.MarkedYAMLError) -> str:
    """PyYAML's problem, its line and column, without the echoed source snippet."""
    reason = f"{err.context}: {err.problem}" if err.context else str(err.problem)
    mark = err.problem_mark or err.context_mark
    if mark is not None:
        reason += f" at line {mark.line + 1}, column {mark.column + 1}"
    return " ".join(reason.split())


_SCALARS = (str, bool, int, float, type(None))


def _check_values(data: Any, source: str) -> None:
    """Walk the parsed data (without recursion) against the depth, size and type limits; only
    containers are stacked, so a long list of numbers is one pass."""
    _check_scalar(data, (), source)
    stack: list[tuple[Any, tuple[Any, ...]]] = [(data, ())] if isinstance(data, dict | list) else []
    count = 1
    while stack:
        value, path = stack.pop()
        if len(path) >= MAX_DEPTH:
            raise RefusedInput(f"nested deeper than {MAX_DEPTH} levels", field=_dotted(path), source=source)
        if isinstance(value, dict):
            for key in value:
                if not isinstance(key, str):
                    raise SpecError(f"key {key!r} is not text (quote it)", field=_dotted(path), source=source)
            children = value.items()
        else:
            children = enumerate(value)
        count += len(value)
        if count > MAX_VALUES:
            raise RefusedInput(f"more than {MAX_VALUES} values in the file", source=source)
        for key, child in children:
            if isinstance(child, dict | list):
                stack.append((child, (*path, key)))
            elif not isinstance(child, _PLAIN):
                _check_scalar(child, (*path, key), source)


_PLAIN = (str, bool, float, type(None))


def _dotted(path: tuple[Any, ...]) -> str:
    return ".".join(str(p) for p in path)


def _check_scalar(value: Any, path: tuple[Any, ...], source: str) -> None:
    if isinstance(value, int) and value.bit_length() > _MAX_INT_BITS:
        raise RefusedInput(f"integer longer than {MAX_INT_DIGITS} digits", field=_dotted(path), source=source)
    if not isinstance(value, (*_SCALARS, dict, list)):
        reason = f"a {type(value).__name__} is not a value gamespec reads (quote it to make it text)"
        raise SpecError(reason, field=_dotted(path), source=source)
