"""Run a study: skip the points already in the store, run the rest through an executor, save each
as it completes, and show a progress bar."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from gamespec.studies.executors import Executor, SerialExecutor, executor
from gamespec.studies.store import ResultStore


def run_study(
    points: Mapping[str, Any],
    fn: Callable[[Any], Any],
    store: ResultStore,
    *,
    executor: Executor | None = None,
    description: str = "study",
    show_progress: bool = True,
    accept: Callable[[Any], bool] | None = None,
) -> dict[str, Any]:
    """Evaluate ``fn(point)`` for every ``key → point`` not yet in ``store``; return all values.
    The progress bar goes to stderr, so stdout stays clean for ``--json``.

    ``fn`` must return JSON-able data. Values already stored are reused (those ``accept`` takes,
    when given; the others are computed again), so an interrupted study resumes where it stopped.
    """
    saved = store.items()
    done = {key for key, value in saved.items() if accept is None or accept(value)}
    todo = [(key, point) for key, point in points.items() if key not in done]
    runner = executor or SerialExecutor()
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
    progress_bar = Progress(*columns, disable=not show_progress, console=Console(stderr=True))
    with progress_bar as progress:
        task = progress.add_task(description, total=len(points), completed=len(points) - len(todo))
        for (_fn, (key, _point)), value in runner.imap(_call, [(fn, item) for item in todo]):
            store.put(key, value)
            progress.advance(task)
    saved = store.items()
    return {key: saved[key] for key in points if key in saved}


def _call(job: tuple[Callable[[Any], Any], tuple[str, Any]]) -> Any:
    fn, (_key, point) = job
    return fn(point)


def stored_rows(
    points: Mapping[str, Any],
    fn: Callable[[Any], Any],
    folder: str | Path,
    *,
    workers: int = 1,
    description: str = "study",
    show_progress: bool = False,
) -> tuple[list[Any], int]:
    """:func:`run_study` into the :class:`ResultStore` at ``folder`` with ``workers`` processes: the
    values in the order of ``points``, and how many were computed now (the others were stored)."""
    store = ResultStore(folder)
    computed = len(points.keys() - store.done())
    values = run_study(
        points, fn, store, executor=executor(workers), description=description, show_progress=show_progress
    )
    return [values[key] for key in points], computed
