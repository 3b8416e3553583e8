"""Hypothesis strategies for problem files: values drawn from each kind's JSON Schema, mutations of
the shipped problem files, raw bytes and text, and ``--set`` assignments."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path
from typing import Any

import yaml
from hypothesis import strategies as st

from tests.conftest import PROBLEMS

SHIPPED = sorted(PROBLEMS.rglob("*.yaml"))

EXPRESSIONS = [
    "t",
    "tau",
    "x1",
    "x2",
    "u",
    "rho",
    "dt",
    "pi",
    "linear",
    "sin(u) + rho*x2",
    "x1**2 + u**2",
    "t_f",
    "-pi/4",
    "3*pi/4",
    "1/0",
    "0/0",
    "log(0)",
    "asin(2)",
    "sqrt(-1)",
    "9**9**9",
    "exp(exp(exp(100)))",
    "exp(1000) - exp(1000)",
    "x1 <= 1",
    "0 <= x1 <= 1",
    "3 <= x1 <= 1",
    "__import__('os').system('true')",
    "().__class__.__bases__",
    "lambda: 0",
    "x1 if u else x2",
    "[1, 2]",
    "-" * 500 + "u",
    "(" * 200 + "u" + ")" * 200,
    "+".join(["u"] * 1500),
    "1e400",
    "nan",
    "inf",
]
"""Expression texts a user might write, and texts an attacker or a typo might: valid, undefined,
infinite, not real, enormous, nested, outside the whitelist."""

NASTY_NUMBERS = [
    0,
    1,
    -1,
    0.5,
    2,
    10,
    1e-300,
    -1e-12,
    1e12,
    1e308,
    -1e308,
    2**63,
    -(2**63),
    10**400,
    math.nan,
    math.inf,
    -math.inf,
]
"""Numbers at the edges: zero, tiny, huge, beyond float range, not finite."""

NASTY = [
    None,
    True,
    False,
    "",
    " ",
    "x-notes",
    [],
    {},
    [[]],
    {"a": None},
    *NASTY_NUMBERS,
    *EXPRESSIONS[:6],
    "é" * 3,
    "\x00",
]

numbers = st.one_of(
    st.sampled_from(NASTY_NUMBERS),
    st.integers(-5, 200),
    st.floats(allow_nan=True, allow_infinity=True),
)
texts = st.one_of(st.sampled_from(EXPRESSIONS), st.text(max_size=16))
names = st.one_of(
    st.sampled_from(["x1", "x2", "u", "v", "rho", "dt", "t", "pi", "sin", "x-y", "pursuers[1]", "1"]),
    st.from_regex(r"[a-z][a-z0-9_]{0,6}", fullmatch=True),
)
scalars = st.one_of(st.none(), st.booleans(), numbers, texts)
values = st.recursive(
    scalars,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(names, inner, max_size=4),
    max_leaves=12,
)


def from_schema(schema: dict[str, Any], defs: dict[str, Any], depth: int = 0) -> st.SearchStrategy[Any]:
    """Values shaped by a JSON Schema (as ``gamespec schema KIND`` prints it), bounds and enums
    honoured most of the time and broken some of the time."""
    if depth > 8:
        return scalars
    if "$ref" in schema:
        target = defs[schema["$ref"].rsplit("/", 1)[-1]]
        return st.deferred(lambda: from_schema(target, defs, depth + 1))
    if "const" in schema:
        return st.just(schema["const"])
    if "enum" in schema:
        return st.sampled_from(schema["enum"])
    for union in ("anyOf", "oneOf"):
        if union in schema:
            return st.one_of([from_schema(s, defs, depth + 1) for s in schema[union]])
    if "allOf" in schema:
        return from_schema(schema["allOf"][0], defs, depth + 1)
    kind = schema.get("type")
    if isinstance(kind, list):
        return st.one_of([from_schema({**schema, "type": k}, defs, depth) for k in kind])
    if kind == "object":
        return _object(schema, defs, depth)
    if kind == "array":
        return _array(schema, defs, depth)
    if kind == "integer":
        low = schema.get("minimum", -3)
        high = schema.get("maximum", low + 40)
        return st.one_of(st.integers(low, high), st.sampled_from([-1, 0, 10**6, 2**63]))
    if kind == "number":
        return numbers
    if kind == "string":
        return texts
    if kind == "boolean":
        return st.booleans()
    if kind == "null":
        return st.none()
    return values


def _object(schema: dict[str, Any], defs: dict[str, Any], depth: int) -> st.SearchStrategy[Any]:
    properties = schema.get("properties", {})
    required = set(schema.get("required", []))
    fixed = {k: from_schema(s, defs, depth + 1) for k, s in properties.items() if k in required}
    optional = {k: from_schema(s, defs, depth + 1) for k, s in properties.items() if k not in required}
    base = st.fixed_dictionaries(fixed, optional=optional)
    extra = schema.get("additionalProperties")
    if isinstance(extra, dict):
        more = st.dictionaries(names, from_schema(extra, defs, depth + 1), max_size=3)
        return st.tuples(base, more).map(lambda pair: {**pair[1], **pair[0]})
    return base


def _array(schema: dict[str, Any], defs: dict[str, Any], depth: int) -> st.SearchStrategy[Any]:
    if "prefixItems" in schema:
        return st.tuples(*(from_schema(s, defs, depth + 1) for s in schema["prefixItems"])).map(list)
    low = schema.get("minItems", 0)
    high = min(schema.get("maxItems", low + 4), low + 4)
    return st.lists(from_schema(schema.get("items", {}), defs, depth + 1), min_size=low, max_size=high)


def schema_documents(kind: str) -> st.SearchStrategy[dict[str, Any]]:
    """Whole problem files of ``kind`` drawn from its JSON Schema."""
    from gamespec.specs.schema import json_schema

    schema = json_schema(kind)
    return from_schema(schema, schema.get("$defs", {})).map(lambda d: {**d, "kind": kind})


def _paths(data: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    found = [prefix]
    if isinstance(data, dict):
        for key, value in data.items():
            found += _paths(value, (*prefix, key))
    elif isinstance(data, list):
        for i, value in enumerate(data):
            found += _paths(value, (*prefix, i))
    return found


def _mutate(data: Any, path: tuple[Any, ...], op: str, value: Any, name: str) -> Any:
    if not path:
        return value if op == "replace" else data
    parent = data
    for part in path[:-1]:
        parent = parent[part]
    last = path[-1]
    if op == "delete":
        del parent[last]
    elif op == "replace":
        parent[last] = value
    elif op == "wrap":
        parent[last] = [parent[last]]
    elif op == "rename" and isinstance(parent, dict):
        parent[name] = parent.pop(last)
    elif op == "typo" and isinstance(parent, dict) and isinstance(last, str) and last:
        parent[last[:-1] + last[-1] * 2] = parent.pop(last)
    elif op == "insert" and isinstance(parent[last], dict):
        parent[last][name] = value
    elif op == "insert" and isinstance(parent[last], list):
        parent[last].append(value)
    return data


@st.composite
def mutated_documents(draw: st.DrawFn) -> tuple[str, Any]:
    """A shipped problem file (its name) with one to four random edits: a key deleted, renamed or
    misspelled, a value replaced by an edge value, wrapped in a list, an entry inserted."""
    path = draw(st.sampled_from(SHIPPED))
    data = yaml.safe_load(path.read_text())
    for _ in range(draw(st.integers(1, 4))):
        where = draw(st.sampled_from(_paths(data)))
        op = draw(st.sampled_from(["delete", "replace", "replace", "wrap", "rename", "typo", "insert"]))
        data = _mutate(data, where, op, copy.deepcopy(draw(values)), draw(names))
    return path.stem, data


@st.composite
def mutated_bytes(draw: st.DrawFn) -> bytes:
    """A shipped problem file's bytes with a few byte-level edits (cut, insert, flip, truncate)."""
    raw = bytearray(draw(st.sampled_from(SHIPPED)).read_bytes())
    for _ in range(draw(st.integers(1, 4))):
        at = draw(st.integers(0, len(raw)))
        op = draw(st.sampled_from(["cut", "insert", "flip", "truncate"]))
        if op == "cut":
            del raw[at : at + draw(st.integers(1, 40))]
        elif op == "insert":
            raw[at:at] = draw(st.binary(min_size=1, max_size=12) | st.sampled_from(_SNIPPETS))
        elif op == "flip" and at < len(raw):
            raw[at] ^= draw(st.integers(1, 255))
        elif op == "truncate":
            del raw[at:]
    return bytes(raw)


_SNIPPETS = [
    b"&a ",
    b"*a",
    b"<<: ",
    b"\xff\xfe",
    b"\t",
    b": ",
    b"- ",
    b"[",
    b"{",
    b"!!python/object ",
    b"!!binary ",
    b"!!set ",
    b"2001-12-14",
    b"9" * 4400,
    b"\n" + b"  " * 40 + b"x: 1\n",
]


def dumped(data: Any, fmt: str) -> str:
    """``data`` written as YAML or JSON (non-standard ``NaN``/``Infinity`` included, as a user may)."""
    if fmt == "json":
        return json.dumps(data)
    return yaml.safe_dump(data, allow_unicode=True)


def write(folder: Path, stem: str, suffix: str, content: str | bytes) -> Path:
    path = folder / f"{stem}{suffix}"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding="utf-8", errors="surrogatepass")
    return path
