"""The rows that lead a ``pursuit_scenario``'s solve summary: who caught whom, and when."""

from __future__ import annotations

from gamespec.result import Result


def scenario_summary(result: Result) -> list[tuple[str, object]]:
    """Captured evaders and the last capture time, then one row per evader: its capture time and
    capturer (P1, P2, ...), or that it escaped to the horizon."""
    times, capturers = result.metrics["capture_times"], result.metrics["capturers"]
    caught = [t for t in times if t is not None]
    rows: list[tuple[str, object]] = [
        ("evaders captured", f"{len(caught)} of {len(times)}"),
        ("last capture time", max(caught) if caught else None),
        ("allocation", f"{result.metrics['algorithm']} ({result.metrics['pursuit_strategy']} pursuit)"),
    ]
    for j, (t, i) in enumerate(zip(times, capturers, strict=True)):
        outcome = f"captured at t = {t:.4g} by P{i + 1}" if t is not None else "escaped to the horizon"
        rows.append((f"E{j + 1}", outcome))
    return [(k, v) for k, v in rows if v is not None]
