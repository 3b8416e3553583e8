"""A study folder as a table: ``gamespec results DIR`` prints it and writes CSV or Parquet.

One row per stored point: its key, the point's scalar fields (nested mappings such as ``metrics``
flattened to dotted names, lists kept as JSON text) and its provenance (``spec_hash``, ``created``,
``versions.<package>``). Each column gets one type (bool, integer, float, or text) so the Parquet
file is typed and a CSV reads back to the same values.
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from gamespec import registry
from gamespec.errors import GamespecError
from gamespec.studies.rows import study_meta, valid_points
from gamespec.studies.store import ResultStore, is_store


def find_store(folder: str | Path) -> ResultStore:
    """The store of a study folder: ``DIR`` itself (a sweep's or compare's ``--out``) or
    ``DIR/points`` (a saved ``pursuit study``); a GamespecError when there is none."""
    folder = Path(folder)
    for candidate in (folder, folder / "points"):
        if is_store(candidate):
            return ResultStore(candidate)
    raise GamespecError(f"{folder}: no study results here (no store.sqlite in it or in points/)")


def _flatten(prefix: str, value: Any, into: dict[str, Any]) -> None:
    if isinstance(value, Mapping):
        for k, v in value.items():
            _flatten(f"{prefix}.{k}" if prefix else str(k), v, into)
    elif isinstance(value, list | tuple):
        into[prefix] = json.dumps(value)
    else:
        into[prefix] = value


def study_rows(store: ResultStore) -> list[dict[str, Any]]:
    """Flat rows of every intact, valid point (:func:`~gamespec.studies.rows.valid_points`; the
    others are reported in ``store.damaged``), provenance included: a sweep's in the order of its
    swept parameters, others in the order they were saved."""
    provenance = store.provenance()
    rows = []
    for key, value in valid_points(store).items():
        row: dict[str, Any] = {"key": key}
        _flatten("", value if isinstance(value, Mapping) else {"value": value}, row)
        _flatten("", provenance[key], row)
        rows.append(row)
    swept = study_meta(store).parameters
    return sorted(
        rows, key=lambda row: [(row.get(p) is None, str(type(row.get(p))), row.get(p)) for p in swept]
    )


def headline_columns(rows: list[dict[str, Any]]) -> list[str]:
    """The headline numbers of the kinds the rows are of (:attr:`gamespec.registry.Kind.columns`),
    those that some row has, in the kinds' order: what a study table shows after its parameters."""
    found: list[str] = []
    for kind in dict.fromkeys(str(row.get("kind", "")) for row in rows):
        if kind in registry.names("gamespec.kinds"):
            found += [c for c in registry.kind(kind).columns if c not in found]
    return [c for c in found if any(row.get(c) is not None for row in rows)]


def columns(rows: list[dict[str, Any]]) -> list[str]:
    """Every column, in first-seen order."""
    return list(dict.fromkeys(name for row in rows for name in row))


def _column_type(values: list[Any]) -> type:
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present):
        return bool
    if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return int
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in present):
        return float
    return str


def typed_columns(rows: list[dict[str, Any]]) -> dict[str, tuple[type, list[Any]]]:
    """Per column: its one type and its values converted to it (None where a row lacks it)."""
    out = {}
    for name in columns(rows):
        values = [row.get(name) for row in rows]
        kind = _column_type(values)
        out[name] = (kind, [None if v is None else kind(v) for v in values])
    return out


def _csv_cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else str(value)
    return str(value)


def write_csv(rows: list[dict[str, Any]], path: str | Path) -> Path:
    """Rows as CSV (floats written exactly, empty cells for missing values)."""
    path = Path(path)
    table = typed_columns(rows)
    try:
        with path.open("w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(table)
            for i in range(len(rows)):
                writer.writerow(_csv_cell(values[i]) for _, values in table.values())
    except OSError as err:
        raise GamespecError(f"{path}: cannot write the CSV ({err.strerror or err})") from None
    return path


def write_parquet(rows: list[dict[str, Any]], path: str | Path) -> Path:
    """Rows as a typed Parquet file (pyarrow)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    arrow = {bool: pa.bool_(), int: pa.int64(), float: pa.float64(), str: pa.string()}
    typed = typed_columns(rows)
    table = pa.table({name: pa.array(values, arrow[kind]) for name, (kind, values) in typed.items()})
    try:
        pq.write_table(table, Path(path))
    except OSError as err:
        raise GamespecError(f"{path}: cannot write the Parquet file ({err})") from None
    return Path(path)
