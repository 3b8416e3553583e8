"""The content hash of a spec (the provenance of Results, the key of the analyses' cache)."""

from __future__ import annotations

import hashlib
import json
import threading
from collections import OrderedDict
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from gamespec.specs.base import SpecBase


RECENT = 64
"""How many specs' hashes are kept by identity (a spec is frozen: its content, and so its hash,
cannot change; a compiled chain re-solved many times hashes the same spec object again)."""
_recent: OrderedDict[int, tuple[SpecBase, str]] = OrderedDict()
_lock = threading.Lock()
"""Guards :data:`_recent` (the points of a threaded executor hash their specs at once)."""


def spec_hash(spec: SpecBase) -> str:
    """A stable hash of a spec's content (provenance of Results)."""
    with _lock:
        kept = _recent.get(id(spec))
        if kept is not None and kept[0] is spec:
            _recent.move_to_end(id(spec))
            return kept[1]
    text = json.dumps(spec.model_dump(mode="json"), sort_keys=True)
    digest = hashlib.sha256(text.encode()).hexdigest()[:16]
    with _lock:
        _recent[id(spec)] = (spec, digest)
        if len(_recent) > RECENT:
            _recent.popitem(last=False)
    return digest
