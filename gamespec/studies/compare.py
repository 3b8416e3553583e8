"""``gamespec compare``: one spec on several backends (and solvers), one row each.

A backend that cannot take the problem (not installed, kind or feature missing) gets a row with
its reason instead of stopping the study.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rich.console import Console

from gamespec.errors import BackendError, GamespecError
from gamespec.specs.base import SpecBase


def parse_backend_list(text: str) -> list[tuple[str, str | None]]:
    """``"casadi,cvxpy:scs"`` → ``[("casadi", None), ("cvxpy", "scs")]``."""
    entries = []
    for item in text.split(","):
        name, _, solver = item.strip().partition(":")
        if not name:
            raise BackendError(f"empty backend name in --backends {text!r}")
        entries.append((name, solver or None))
    return entries


def compare_backends(
    spec: SpecBase,
    entries: list[tuple[str, str | None]],
    *,
    out: Path | None = None,
    progress: Console | None = None,
) -> list[dict[str, Any]]:
    """Solve ``spec`` on each ``(backend, solver)``; rows with status, objective, times, checks and
    the relative objective gap to the best optimal row."""
    from gamespec.solving import solve

    rows: list[dict[str, Any]] = []
    for name, solver in entries:
        label = f"{name}:{solver}" if solver else name
        options = {"solver": solver} if solver else None
        try:
            if progress is not None:
                with progress.status(f"solving on {label} ..."):
                    result = solve(spec, name, options=options)
            else:
                result = solve(spec, name, options=options)
        except GamespecError as err:
            rows.append({"backend": label, "status": "unsupported", "reason": str(err)})
            continue
        if out is not None:
            result.save(Path(out) / label.replace(":", "_"))
        rows.append({**result.summary(), "backend": label})
    best = [r["objective"] for r in rows if r.get("status") == "optimal" and r.get("objective") is not None]
    sense = getattr(getattr(spec, "problem", None), "objective", None)
    maximize = getattr(sense, "sense", "minimize") == "maximize"
    if best:
        ref = max(best) if maximize else min(best)
        for r in rows:
            if r.get("objective") is not None:
                r["relative_gap"] = abs(r["objective"] - ref) / max(abs(ref), 1e-12)
    return rows
