"""A study's results on disk: one SQLite database per study folder, in WAL mode.

Each finished point is one row ``(key, value JSON, digest, provenance)``; a batch of rows is one
transaction, committed with ``synchronous=FULL`` (fsynced before :meth:`ResultStore.put_many`
returns), so a crash or a power loss leaves every committed point intact and no half-written one.
A record whose digest, JSON or column types no longer check out is reported
(:attr:`ResultStore.damaged`) and left out, so the study computes it again (and so is a value of the
wrong shape for its study, :mod:`gamespec.studies.rows`); a database file that SQLite cannot read
at all, or whose tables are not these, is moved aside (``store.sqlite.damaged-<time>``) and a
fresh one started. 10⁵ points are 10⁵ rows of one file. ``meta`` holds what the study was (sweep
or compare, its parameters) for ``gamespec results`` and ``gamespec plot``.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import sqlite3
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from gamespec.errors import GamespecError

FILENAME = "store.sqlite"

_SCHEMA = """
CREATE TABLE IF NOT EXISTS points (
    key TEXT PRIMARY KEY,
    value TEXT NOT NULL,
    digest TEXT NOT NULL,
    spec_hash TEXT,
    versions TEXT,
    created TEXT NOT NULL
);
CREATE TABLE IF NOT EXISTS meta (name TEXT PRIMARY KEY, value TEXT NOT NULL);
"""


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def is_store(folder: str | Path) -> bool:
    """Whether ``folder`` holds a study store."""
    return (Path(folder) / FILENAME).is_file()


class ResultStore:
    """The points of one study folder (created if needed)."""

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        if self.folder.exists() and not self.folder.is_dir():
            raise GamespecError(f"{self.folder}: is a file, not a folder for study results")
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise GamespecError(f"{self.folder}: cannot write there ({err.strerror or err})") from None
        self.path = self.folder / FILENAME
        if (self.path.is_symlink() or self.path.exists()) and not self.path.is_file():
            raise GamespecError(
                f"{self.path}: not a regular file (a FIFO, a device, a folder or a broken link)"
            )
        self._unreadable: list[str] = []
        self._damaged_records: list[str] = []
        self._db = self._open()

    @property
    def damaged(self) -> list[str]:
        """What was found damaged: the file on opening, records on the last read."""
        return self._unreadable + self._damaged_records

    def _connect(self) -> sqlite3.Connection:
        db = sqlite3.connect(self.path, isolation_level=None, timeout=30)
        db.execute("PRAGMA journal_mode=WAL")
        db.execute("PRAGMA synchronous=FULL")
        db.executescript(_SCHEMA)
        (verdict,) = db.execute("PRAGMA quick_check").fetchone()
        if verdict == "ok":
            verdict = _schema_problem(db)
        if verdict != "ok":
            db.close()
            raise sqlite3.DatabaseError(verdict)
        return db

    def _open(self) -> sqlite3.Connection:
        try:
            return self._connect()
        except sqlite3.OperationalError as err:
            raise GamespecError(
                f"{self.path}: cannot open the study store ({' '.join(str(err).split())})"
            ) from None
        except sqlite3.DatabaseError as err:
            stamp = _dt.datetime.now(_dt.UTC).strftime("%Y%m%dT%H%M%S")
            aside = self.path.with_name(f"{FILENAME}.damaged-{stamp}")
            self.path.rename(aside)
            for suffix in ("-wal", "-shm"):
                self.path.with_name(FILENAME + suffix).unlink(missing_ok=True)
            why = " ".join(str(err).split())
            self._unreadable.append(f"{self.path}: unreadable ({why}); moved to {aside.name}, starting anew")
            return self._connect()

    def close(self) -> None:
        self._db.close()

    def put(
        self, key: str, value: Any, *, spec_hash: str | None = None, versions: Mapping | None = None
    ) -> None:
        """Save one point's value (JSON-able), durably."""
        self.put_many([(key, value, spec_hash, versions)])

    def put_many(self, records: Iterable[tuple[str, Any, str | None, Mapping | None]]) -> None:
        """Save ``(key, value, spec_hash, versions)`` records in one fsynced transaction."""
        now = _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")
        rows = []
        for key, value, spec_hash, versions in records:
            text = json.dumps(value)
            rows.append((key, text, _digest(text), spec_hash, json.dumps(versions or {}), now))
        with self._db:
            self._db.execute("BEGIN IMMEDIATE")
            self._db.executemany("INSERT OR REPLACE INTO points VALUES (?, ?, ?, ?, ?, ?)", rows)

    def _intact(self) -> dict[str, tuple[Any, dict[str, Any]]]:
        found: dict[str, tuple[Any, dict[str, Any]]] = {}
        self._damaged_records = []
        try:
            rows = self._db.execute(
                "SELECT key, value, digest, spec_hash, versions, created FROM points"
            ).fetchall()
        except sqlite3.DatabaseError as err:
            raise GamespecError(f"{self.path}: cannot read the study store ({err})") from None
        for row in rows:
            try:
                key, value, provenance = _checked_row(row)
            except ValueError as err:
                self.report_damaged(row[0], str(err))
                continue
            found[key] = (value, provenance)
        return found

    def report_damaged(self, key: object, why: str) -> None:
        """Add a damaged record to :attr:`damaged` (``why``: its digest, its JSON, its shape)."""
        shown = key if isinstance(key, str) else repr(key)
        self._damaged_records.append(f"{self.path}: record {shown!r} is damaged ({why}); computing it again")

    def done(self) -> set[str]:
        """Keys saved intact."""
        return set(self._intact())

    def items(self) -> dict[str, Any]:
        """All intact ``key → value``."""
        return {key: value for key, (value, _) in self._intact().items()}

    def provenance(self) -> dict[str, dict[str, Any]]:
        """Per intact key: the spec hash, the worker's package versions and the time it was saved."""
        return {key: prov for key, (_, prov) in self._intact().items()}

    def set_meta(self, name: str, value: Any) -> None:
        """Record what the study is (kind, parameters, problem), durably."""
        with self._db:
            self._db.execute("BEGIN IMMEDIATE")
            self._db.execute("INSERT OR REPLACE INTO meta VALUES (?, ?)", (name, json.dumps(value)))

    def meta(self, name: str) -> Any:
        """A recorded meta value, or None (also when it is damaged: reported in :attr:`damaged`)."""
        try:
            row = self._db.execute("SELECT value FROM meta WHERE name = ?", (name,)).fetchone()
        except sqlite3.DatabaseError as err:
            raise GamespecError(f"{self.path}: cannot read the study store ({err})") from None
        if row is None:
            return None
        try:
            if not isinstance(row[0], str):
                raise ValueError(f"its value is {type(row[0]).__name__}, not JSON text")
            return json.loads(row[0])
        except (ValueError, RecursionError) as err:
            self._unreadable.append(f"{self.path}: meta {name!r} is damaged ({err}); ignored")
            return None


_COLUMNS = {
    "points": ["key", "value", "digest", "spec_hash", "versions", "created"],
    "meta": ["name", "value"],
}


def _schema_problem(db: sqlite3.Connection) -> str:
    """``ok`` when the tables have the columns of :data:`_SCHEMA`, else what differs."""
    for table, expected in _COLUMNS.items():
        found = [row[1] for row in db.execute(f"PRAGMA table_info({table})")]
        if found != expected:
            return f"table {table} has columns {found}, not {expected}"
    return "ok"


def _checked_row(row: tuple[Any, ...]) -> tuple[str, Any, dict[str, Any]]:
    """``(key, value, provenance)`` of one ``points`` row; ValueError saying what is wrong with it
    (SQLite keeps any type in any column: each is checked before it is used)."""
    key, text, digest, spec_hash, versions, created = row
    for name, value in (("key", key), ("value", text), ("digest", digest), ("created", created)):
        if not isinstance(value, str):
            raise ValueError(f"its {name} is {type(value).__name__}, not text")
    if not isinstance(spec_hash, str | None) or not isinstance(versions, str):
        raise ValueError("its provenance is not text")
    if _digest(text) != digest:
        raise ValueError("its digest does not match")
    try:
        value = json.loads(text)
        packages = json.loads(versions)
    except RecursionError:
        raise ValueError("its JSON is nested too deeply") from None
    if not isinstance(packages, dict) or not all(isinstance(v, str) for v in packages.values()):
        raise ValueError("its package versions are not a mapping of names to versions")
    return key, value, {"spec_hash": spec_hash, "versions": packages, "created": created}
