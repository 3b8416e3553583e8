"""Hypothesis strategies for saved inputs: tampered Result folders and tampered study stores, made
from the seeds in ``tests/fuzz/saved/`` (:mod:`tests.fuzz.make_saved`).

A tampering is drawn, not listed: a JSON field of a Result replaced by a value of another type or
shape (or removed, or its kind swapped), an ``.npy`` member's header, dtype, shape or data rewritten
(or the zip's flags and bytes), a file replaced by a FIFO, a device, a folder or a link out of the
folder; a store's rows given other JSON, other column types or a wrong digest, its ``study`` meta
record another shape, its tables other columns, its file cut short or its bytes flipped.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
import sqlite3
import struct
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import strategies as st

SAVED = Path(__file__).resolve().parent / "saved"
RESULTS = sorted((SAVED / "results").iterdir()) if (SAVED / "results").is_dir() else []
STORES = sorted((SAVED / "stores").iterdir()) if (SAVED / "stores").is_dir() else []
KINDS = sorted({json.loads((r / "result.json").read_text())["kind"] for r in RESULTS})

Tamper = Callable[[Path], None]
"""A change to a copied folder, in place."""

WRONG_VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([0, -1, 1, 2, 10**15, float("nan"), float("inf"), -float("inf"), 1e308, -0.0]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["", "0", "1.5", "abc", "nan", "x", "pursuer", "__import__('os')", "a/b"]),
    st.text(max_size=8),
    st.lists(st.sampled_from([0, 1.5, "x", None, [], {}]), max_size=4),
    st.dictionaries(
        st.sampled_from(["x", "y", "name", "0"]), st.sampled_from([0, "x", None, []]), max_size=3
    ),
)
"""Values of another type or shape than a field expects."""


def _paths(value: Any, prefix: tuple = ()) -> list[tuple]:
    """Every path into a JSON value (keys and list indices), the root excluded."""
    found = []
    if isinstance(value, dict):
        items = value.items()
    elif isinstance(value, list):
        items = enumerate(value)
    else:
        return found
    for key, child in items:
        found.append((*prefix, key))
        found.extend(_paths(child, (*prefix, key)))
    return found


def _set(document: Any, path: tuple, value: Any) -> None:
    for key in path[:-1]:
        document = document[key]
    if value is _DELETE:
        del document[path[-1]]
    else:
        document[path[-1]] = value


_DELETE = object()


@st.composite
def json_tampering(draw: st.DrawFn) -> tuple[str, Tamper]:
    """A field of ``result.json`` replaced (wrong type or shape), removed, or the kind swapped."""
    how = draw(st.sampled_from(["replace", "replace", "delete", "kind", "metrics_of_another"]))
    other = draw(st.sampled_from(RESULTS))
    kind = draw(st.sampled_from([*KINDS, "no_such_kind", ""]))
    pick = draw(st.integers(min_value=0, max_value=10**6))
    value = draw(WRONG_VALUES)

    def tamper(folder: Path) -> None:
        document = json.loads((folder / "result.json").read_text())
        paths = _paths(document)
        if how == "kind":
            document["kind"] = kind
        elif how == "metrics_of_another":
            document["metrics"] = json.loads((other / "result.json").read_text())["metrics"]
        else:
            _set(document, paths[pick % len(paths)], value if how == "replace" else _DELETE)
        (folder / "result.json").write_text(json.dumps(document))

    return f"json {how} #{pick} = {value!r} / {kind}", tamper


DESCRS = ["<f8", ">f8", "<i8", "|b1", "<U3", "<c16", "|O", "<V8", "|S5", "<f3", "<u2", "<M8", "|u1"]

HEADERS = st.one_of(
    st.builds(
        lambda d, f, s: f"{{'descr': '{d}', 'fortran_order': {f}, 'shape': {s}, }}",
        st.sampled_from(DESCRS),
        st.sampled_from(["False", "True", "0", "None"]),
        st.one_of(
            st.lists(st.integers(min_value=0, max_value=10**16), max_size=10).map(
                lambda dims: "(" + "".join(f"{d}, " for d in dims) + ")"
            ),
            st.sampled_from(["(3)", "()", "(-1,)", "[3]", "(1e3,)", "(3, x)"]),
        ),
    ),
    st.sampled_from(
        [
            "{'descr': __import__('os').system('touch /tmp/gamespec-pwned'), "
            "'shape': (3,), 'fortran_order': False}",
            "{'descr': '<f8', 'fortran_order': False, 'shape': (3,), 'extra': 1, }",
            "{'descr': [('a', '<f8')], 'fortran_order': False, 'shape': (3,), }",
            "{'descr': '<f8', 'fortran_order': False, 'shape': (3,)",
            "",
        ]
    ),
    st.text(max_size=60),
)
"""``.npy`` headers: plausible ones with any dtype and shape (huge, negative, not tuples), code,
structures, unterminated text, random text."""


def _npy(header: str, data: bytes) -> bytes:
    text = header.encode("latin-1", "replace")
    text += b" " * ((64 - (len(text) + 11) % 64) % 64) + b"\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(text)) + text + data


def _members(npz: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(npz) as archive:
        return {info.filename: archive.read(info) for info in archive.infolist()}


def _write_members(npz: Path, members: dict[str, bytes]) -> None:
    with zipfile.ZipFile(npz, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in members.items():
            archive.writestr(name, data)


@st.composite
def npz_tampering(draw: st.DrawFn) -> tuple[str, Tamper]:
    """A member of ``arrays.npz`` given another header, shape, dtype or data; a member removed,
    renamed or added; the zip's flags set or its bytes flipped or cut."""
    how = draw(
        st.sampled_from(["header", "header", "reshape", "retype", "drop", "rename", "add", "flags", "bytes"])
    )
    pick = draw(st.integers(min_value=0, max_value=10**6))
    header = draw(HEADERS)
    data = draw(st.binary(max_size=64))
    shape = tuple(draw(st.lists(st.integers(min_value=0, max_value=5), max_size=4)))
    dtype = draw(st.sampled_from(["float64", "int64", "bool", "complex128", "<U2", ">f4"]))
    name = draw(
        st.sampled_from(["time.npy", "states/x.npy", "arrays/path_evader.npy", "nope.npy", "x", "arrays/"])
    )
    flag = draw(st.sampled_from([0x1, 0x40, 0x2000, 0x8]))
    offsets = draw(st.lists(st.integers(min_value=0, max_value=10**6), min_size=1, max_size=8))

    def tamper(folder: Path) -> None:
        npz = folder / "arrays.npz"
        if how == "bytes":
            raw = bytearray(npz.read_bytes())
            for offset in offsets:
                raw[offset % len(raw)] ^= 0xFF
            npz.write_bytes(bytes(raw[: max(offsets) % (len(raw) + 1)] if len(offsets) > 4 else raw))
            return
        members = _members(npz)
        key = sorted(members)[pick % len(members)]
        if how == "header":
            members[key] = _npy(header, data)
        elif how in ("reshape", "retype"):
            old = np.load(io.BytesIO(members[key]), allow_pickle=False)
            new = np.resize(old, shape) if how == "reshape" else old
            buffer = io.BytesIO()
            np.save(buffer, new.astype(dtype) if how == "retype" and old.dtype.kind != "U" else new)
            members[key] = buffer.getvalue()
        elif how == "drop":
            del members[key]
        elif how == "rename":
            members[name] = members.pop(key)
        elif how == "add":
            members[name] = _npy(header, data)
        _write_members(npz, members)
        if how == "flags":
            raw = bytearray(npz.read_bytes())
            for signature, at in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
                start = raw.find(signature)
                while start >= 0:
                    raw[start + at] |= flag & 0xFF
                    raw[start + at + 1] |= flag >> 8
                    start = raw.find(signature, start + 4)
            npz.write_bytes(bytes(raw))

    return f"npz {how} #{pick} {header[:40]!r} {shape} {dtype} {name}", tamper


@st.composite
def file_tampering(draw: st.DrawFn) -> tuple[str, Tamper]:
    """``result.json`` or ``arrays.npz`` replaced by a FIFO, a device, a folder, a link out of the
    folder, a dangling link, an empty file, or removed."""
    target = draw(st.sampled_from(["result.json", "arrays.npz"]))
    how = draw(
        st.sampled_from(
            ["fifo", "/dev/zero", "/dev/null", "folder", "outside", "dangling", "empty", "remove"]
        )
    )

    def tamper(folder: Path) -> None:
        path = folder / target
        path.unlink()
        if how == "fifo":
            os.mkfifo(path)
        elif how.startswith("/dev/"):
            path.symlink_to(how)
        elif how == "folder":
            path.mkdir()
        elif how == "outside":
            outside = folder.parent / f"outside-{target}"
            shutil.copy(RESULTS[0] / target, outside)
            path.symlink_to(outside)
        elif how == "dangling":
            path.symlink_to(folder / "nowhere")
        elif how == "empty":
            path.write_bytes(b"")

    return f"file {target} {how}", tamper


def result_tampering() -> st.SearchStrategy[tuple[str, Tamper]]:
    """Any tampering of a Result folder."""
    return st.one_of(json_tampering(), npz_tampering(), file_tampering())


JSON_TEXTS = st.one_of(
    WRONG_VALUES.map(lambda v: json.dumps(v)),
    st.sampled_from(["{", "", "[[[[", "null", '{"status": 1}', '{"status": "optimal", "v": "x"}']),
    st.text(max_size=20),
)

SQL_VALUES = st.one_of(
    st.none(),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.floats(),
    st.binary(max_size=8),
    JSON_TEXTS,
)


@st.composite
def store_tampering(draw: st.DrawFn) -> tuple[str, Tamper]:
    """A study store's row or meta record rewritten (JSON of another shape, another column type, a
    matching or wrong digest), its tables given other columns, its file cut or its bytes flipped,
    or the file replaced by a FIFO or a folder."""
    how = draw(
        st.sampled_from(
            ["value", "value", "column", "meta", "meta", "schema", "delete", "truncate", "bytes", "fifo"]
        )
    )
    column = draw(st.sampled_from(["key", "value", "digest", "spec_hash", "versions", "created"]))
    text = draw(JSON_TEXTS)
    raw = draw(SQL_VALUES)
    keep_digest = draw(st.booleans())
    meta = draw(
        st.one_of(
            JSON_TEXTS,
            st.fixed_dictionaries(
                {"type": st.sampled_from(["sweep", "compare", "x", 1, None]), "parameters": WRONG_VALUES}
            ).map(json.dumps),
        )
    )
    pick = draw(st.integers(min_value=0, max_value=10**6))

    def tamper(folder: Path) -> None:
        path = folder / "store.sqlite"
        if how in ("truncate", "bytes", "fifo"):
            data = bytearray(path.read_bytes())
            path.unlink()
            if how == "fifo":
                os.mkfifo(path)
                return
            if how == "truncate":
                data = data[: pick % len(data)]
            else:
                for k in range(8):
                    data[(pick * (k + 1) * 7919) % len(data)] ^= 0x5A
            path.write_bytes(bytes(data))
            return
        db = sqlite3.connect(path, isolation_level=None)
        try:
            keys = [row[0] for row in db.execute("SELECT key FROM points")]
            key = keys[pick % len(keys)]
            if how == "value":
                from gamespec.studies.store import _digest

                digest = _digest(text) if keep_digest else "0"
                db.execute("UPDATE points SET value = ?, digest = ? WHERE key = ?", (text, digest, key))
            elif how == "column":
                with contextlib.suppress(sqlite3.IntegrityError):  # NOT NULL, PRIMARY KEY
                    db.execute(f"UPDATE points SET {column} = ? WHERE key = ?", (raw, key))
            elif how == "meta":
                db.execute("INSERT OR REPLACE INTO meta VALUES ('study', ?)", (meta,))
            elif how == "schema":
                db.execute("DROP TABLE meta")
                db.execute("CREATE TABLE meta (name TEXT, value TEXT, extra INTEGER)")
            elif how == "delete":
                db.execute("DELETE FROM points WHERE key = ?", (key,))
        finally:
            db.close()

    return f"store {how} #{pick} {column} {text!r} {raw!r} {meta!r}", tamper
