"""A study's results on disk, one JSON file per finished point, written atomically.

A crash loses at most the runs in flight; a rerun asks :meth:`ResultStore.done` and skips what is
there. Keys are the points' own stable names (e.g. ``v=0.5,r2=1.4,psi=-0.5``), hashed into file
names.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any


class ResultStore:
    """A folder of ``<hash>.json`` records ``{"key": ..., "value": ...}``."""

    def __init__(self, folder: str | Path) -> None:
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)

    def _path(self, key: str) -> Path:
        return self.folder / f"{hashlib.sha256(key.encode()).hexdigest()[:20]}.json"

    def put(self, key: str, value: Any) -> None:
        """Save one point's value (JSON-able), atomically."""
        target = self._path(key)
        tmp = target.with_suffix(".tmp")
        tmp.write_text(json.dumps({"key": key, "value": value}))
        os.replace(tmp, target)

    def done(self) -> set[str]:
        """Keys already saved."""
        return {record["key"] for record in self._records()}

    def items(self) -> dict[str, Any]:
        """All saved ``key → value``."""
        return {record["key"]: record["value"] for record in self._records()}

    def _records(self) -> Iterator[dict[str, Any]]:
        for path in sorted(self.folder.glob("*.json")):
            yield json.loads(path.read_text())
