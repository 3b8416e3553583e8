"""``gamespec compare``: one spec on several backends (and solvers), one row each.

A backend that cannot take the problem (not installed, kind or feature missing) gets a row with
its reason instead of stopping the study. With ``out``, each backend's Result is saved in its own
folder and the rows go into the folder's study store (``gamespec results`` / ``plot`` read it).
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Callable
from pathlib import Path
from typing import Any

from rich import box
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from gamespec.errors import BackendError, GamespecError
from gamespec.specs.base import SpecBase
from gamespec.studies.runner import worker_versions
from gamespec.studies.store import ResultStore


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
    """Solve ``spec`` on each ``(backend, solver)``; rows with status, objective, times, checks, the
    checks that failed (``failed_checks``: each value against its tolerance) and the relative
    objective gap to the best optimal row."""
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
        except Exception as err:  # a backend's own failure must not stop the study
            rows.append({"backend": label, "status": "error", "reason": f"{type(err).__name__}: {err}"})
            continue
        if out is not None:
            result.save(Path(out) / label.replace(":", "_"))
        failed = "; ".join(str(f) for f in result.failed_checks())
        rows.append({**result.summary(), "backend": label} | ({"failed_checks": failed} if failed else {}))
    best = [r["objective"] for r in rows if _trusted(r)]
    if best:
        ref = reference_objective(best, spec.objective_sense)
        for r in rows:
            if r.get("objective") is not None:
                r["relative_gap"] = abs(r["objective"] - ref) / max(abs(ref), 1e-12)
    if out is not None:
        _store_rows(spec, rows, Path(out))
    return rows


def reference_objective(objectives: list[float], sense: str) -> float:
    """J* of the gap column: the best trusted objective (lowest when minimizing, highest when
    maximizing), or, for a saddle-point game (``sense == "saddle"``), whose value no backend can
    beat, their median, so that the gap measures disagreement rather than ranking the rows."""
    if sense == "maximize":
        return max(objectives)
    if sense == "minimize":
        return min(objectives)
    return float(statistics.median(objectives))


def _store_rows(spec: SpecBase, rows: list[dict[str, Any]], out: Path) -> None:
    """The comparison as a study store in ``out``: one record per backend label."""
    from gamespec.specs.hashing import spec_hash

    store = ResultStore(out)
    labels = [row["backend"] for row in rows]
    store.set_meta("study", {"type": "compare", "problem": spec.name, "backends": labels})
    store.put_many((row["backend"], row, spec_hash(spec), worker_versions()) for row in rows)
    store.close()


FEASIBILITY_TOL = 1e-6
"""Largest constraint violation of a row whose objective may serve as the reference J*."""


def _trusted(row: dict[str, Any]) -> bool:
    """An optimal row with an objective and no constraint violation beyond the tolerance."""
    violation = row.get("max_constraint_violation")
    feasible = violation is None or (math.isfinite(violation) and violation <= FEASIBILITY_TOL)
    return row.get("status") == "optimal" and row.get("objective") is not None and feasible


def _number(value: float) -> str:
    return f"{value:.6g}"


def _milliseconds(value: float) -> str:
    return f"{value * 1e3:.1f}"


def _magnitude(value: float) -> str:
    return "0" if value == 0 else f"{value:.0e}"


def _gap(value: float) -> str:
    return "0" if value == 0 else f"{value:.1e}"


COLUMNS: list[tuple[str, str, Callable[[Any], str]]] = [
    ("backend", "backend", str),
    ("status", "status", str),
    ("objective", "objective", _number),
    ("t_final", "t_f", _number),
    ("build_time_s", "build", _milliseconds),
    ("solve_time_s", "solve", _milliseconds),
    ("iterations", "iter", str),
    ("max_constraint_violation", "viol", _magnitude),
    ("max_defect", "defect", _magnitude),
    ("relative_gap", "gap", _gap),
]
"""Row key, header and format of each column of the comparison table (fits 80 columns)."""

LEGEND = (
    "build, solve: wall time in ms; viol: max constraint violation; defect: max dynamics defect, "
    "recomputed without the solver; gap: |J - J*| / |J*| to the best optimal objective J* among "
    "rows with no constraint violation above 1e-6 (for a saddle-point game, their median)."
)


def _cell(value: Any, fmt: Callable[[Any], str]) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "—"
    return fmt(value)


def comparison_table(rows: list[dict[str, Any]], title: str) -> Table:
    """The rows of :func:`compare_backends` as one compact table (reasons go in :func:`row_notes`)."""
    table = Table(title=title, box=box.SIMPLE_HEAD, show_edge=False, padding=0)
    for key, header, _ in COLUMNS:
        table.add_column(header, justify="left" if key in ("backend", "status") else "right")
    for row in rows:
        cells = [escape(_cell(row.get(key), fmt)) for key, _, fmt in COLUMNS]
        colour = "green" if row.get("status") == "optimal" else "yellow"
        cells[1] = f"[{colour}]{cells[1]}[/{colour}]"
        table.add_row(*cells)
    return table


def row_notes(rows: list[dict[str, Any]]) -> list[str]:
    """One line per row that is not optimal: the checks that failed (value against tolerance, the
    status policy's reason), else the backend's reason or the solver's message."""
    notes = []
    for row in rows:
        if row.get("status") != "optimal":
            if row.get("failed_checks"):
                why = f"failed check(s) {row['failed_checks']}"
            else:
                why = row.get("reason") or row.get("message") or "no message"
            notes.append(f"{row['backend']}: {why}")
    return notes
