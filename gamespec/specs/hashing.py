"""The content hash of a spec (the provenance of Results, the key of the analyses' cache)."""

from __future__ import annotations

import hashlib
import json
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from gamespec.specs.base import SpecBase


def spec_hash(spec: SpecBase) -> str:
    """A stable hash of a spec's content (provenance of Results)."""
    text = json.dumps(spec.model_dump(mode="json"), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]
