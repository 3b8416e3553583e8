"""What ``gamespec solve`` prints first: the outcome of a Result in the terms of its kind.

A kind registers a summary function in the ``gamespec.summaries`` entry-point group:
``summary(result) -> list[tuple[str, object]]``, rows that lead the solve table (capture time and
capturing set, arcs, per-evader captures, terminal statistics against the target) and ``hint``
rows that point to a better backend where one exists. It reads the Result only.
"""

from __future__ import annotations

from gamespec import registry
from gamespec.result import Result

Rows = list[tuple[str, object]]


def outcome(result: Result) -> Rows:
    """The kind's summary rows of ``result`` (none when the kind registers no summary)."""
    if result.kind not in registry.names("gamespec.summaries"):
        return []
    return registry.load("gamespec.summaries", result.kind)(result)


def optimal_control_summary(result: Result) -> Rows:
    """The objective and the final time of an ``optimal_control`` Result."""
    return [("objective J", result.objective), ("t_f", result.t_final)]


def multiphase_summary(result: Result) -> Rows:
    """The objective, the final time and each phase's span of a ``multiphase_optimal_control`` Result."""
    spans = [
        (f"phase {p['name']}", f"{p['start']:.6g} to {p['end']:.6g}")
        for p in result.metrics.get("phases", [])
    ]
    return [*optimal_control_summary(result), *spans]
