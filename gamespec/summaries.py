"""What ``gamespec solve`` prints first: the outcome of a Result in the terms of its kind.

A kind names a summary function in its :class:`~gamespec.registry.Kind` (``summary``), and so may
each transform (its ``summary``, :class:`~gamespec.transforms.base.Transform`):
``summary(result) -> list[tuple[str, object]]``, rows that lead the solve table (capture time and
capturing set, arcs, per-evader captures, terminal statistics against the target) and ``hint``
rows that point to a better backend where one exists. It reads the Result only. Every kind's rows
end with one ``failed check`` row per check that kept the Result from ``optimal`` (its value and
tolerance, :meth:`~gamespec.result.Result.failed_checks`) and one ``check left out`` row per check
that does not apply, with the reason (``metrics["checks_skipped"]``).
"""

from __future__ import annotations

from gamespec.result import Result

Rows = list[tuple[str, object]]


def outcome(result: Result) -> Rows:
    """The kind's summary rows of ``result`` (none when the kind names no summary or is not
    installed), the rows of each transform the chain applied that names one (the desensitization's
    sensitivities and Monte Carlo, the RCS collision probability), then the failed and the left-out
    checks."""
    return result.summary_rows() + check_rows(result)


def headline(result: Result) -> str:
    """The one-line summary over the solve table: problem, backend, status, and the checks that kept
    the Result from ``optimal`` where there are any."""
    line = f"{result.problem} on {result.backend}: {result.status.value}"
    failed = [f.name for f in result.failed_checks()]
    return f"{line} (failed: {', '.join(failed)})" if failed else line


def check_rows(result: Result) -> Rows:
    """One ``failed check`` row per failed check (value against tolerance), one ``check left out``
    row per check that does not apply (name: reason)."""
    failed = [("failed check", str(f)) for f in result.failed_checks()]
    skipped = result.metrics.get("checks_skipped", {})
    return failed + [("check left out", f"{name}: {why}") for name, why in skipped.items()]


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
