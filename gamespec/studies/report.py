"""The rows that lead a point study's solve summary (Table 2.1, §6.4.4): how many points there are,
how many solved, how many were computed in this run rather than read back, and where they are
stored."""

from __future__ import annotations

from gamespec.result import Result


def study_summary(result: Result) -> list[tuple[str, object]]:
    """Points, solved points (when the study counts them), computed now, and the store's path."""
    m = result.metrics
    rows = [
        ("points", m.get("points")),
        ("solved", m.get("solved")),
        ("computed in this run", m.get("computed")),
        ("store", m.get("store")),
    ]
    return [(k, v) for k, v in rows if v is not None]
