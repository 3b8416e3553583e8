"""Run a study: skip the points already in the store, run the rest through an executor in chunks,
save each chunk as it arrives, and say what was reused.

Points go out in chunks of consecutive points (grid order, so a chunk mostly reuses one compiled
model per worker): a chunk is one task, which keeps per-task overhead (pickling, scheduling, a
round trip) small against the work. Each value is saved with its provenance: the study's spec hash
and the package versions of the worker that computed it.
"""

from __future__ import annotations

import math
import platform
import socket
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from functools import cache
from importlib.metadata import PackageNotFoundError, version
from typing import Any

from gamespec.studies.executors import Executor, SerialExecutor
from gamespec.studies.store import ResultStore
from gamespec.terminal import progress

PROVENANCE_PACKAGES = ("gamespec", "numpy", "scipy", "casadi", "pyomo", "cvxpy")

TASKS_PER_WORKER = 32
"""Chunks per worker a study is cut into at least (load balance at the end of a run)."""

MAX_CHUNK = 32
"""Most points in one task (what a worker that dies mid-chunk has to redo)."""


@cache
def worker_versions() -> dict[str, str]:
    """Python, host and the versions of the packages that shape a result, in this process."""
    found = {"python": platform.python_version(), "host": socket.gethostname()}
    for name in PROVENANCE_PACKAGES:
        try:
            found[name] = version(name)
        except PackageNotFoundError:
            continue
    return found


def chunk_size(points: int, workers: int) -> int:
    """Points per task: one for a single worker, else enough for ``TASKS_PER_WORKER`` tasks per
    worker, at most ``MAX_CHUNK``."""
    if workers <= 1:
        return 1
    return max(1, min(MAX_CHUNK, math.floor(points / (TASKS_PER_WORKER * workers))))


@dataclass
class StudyRun:
    """The values of a study (in the order of its points) and what this run did."""

    values: dict[str, Any]
    computed: int
    reused: int


def _evaluate_chunk(job: tuple[Callable[[Any], Any], list[tuple[str, Any]]]) -> list[tuple[str, Any, dict]]:
    """Worker side: every point of one chunk, with the worker's versions."""
    fn, chunk = job
    return [(key, fn(point), worker_versions()) for key, point in chunk]


def run_study(
    points: Mapping[str, Any],
    fn: Callable[[Any], Any],
    store: ResultStore,
    *,
    executor: Executor | None = None,
    description: str = "study",
    show_progress: bool = True,
    accept: Callable[[Any], bool] | None = None,
    spec_hash: str | None = None,
    report: Callable[[str], None] | None = None,
) -> StudyRun:
    """Evaluate ``fn(point)`` for every ``key → point`` not yet in ``store``; all values.

    ``fn`` must return JSON-able data. Values already stored are reused (those ``accept`` takes,
    when given; the others are computed again), so an interrupted study resumes where it stopped;
    damaged records are reported and computed again. ``report`` gets one line for each damaged
    record and, on a resumed run, the number of points reused (default: stderr). Progress goes to
    stderr too, so stdout stays clean for ``--json``: a bar on a terminal, a plain line every few
    seconds elsewhere (:func:`gamespec.terminal.progress`; ``--quiet`` silences it).
    """
    say = report or (lambda line: print(line, file=sys.stderr))
    saved = store.items()
    for line in store.damaged:
        say(line)
    done = {key for key, value in saved.items() if accept is None or accept(value)}
    todo = [(key, point) for key, point in points.items() if key not in done]
    reused = len(points) - len(todo)
    if reused:
        say(f"resuming: {reused} of {len(points)} points reused from {store.path}")
    runner = executor or SerialExecutor()
    with runner, progress(description, total=len(points), enabled=show_progress) as tracker:
        tracker.advance(reused)
        size = chunk_size(len(todo), runner.workers)
        jobs = [(fn, todo[i : i + size]) for i in range(0, len(todo), size)]
        for _job, records in runner.imap(_evaluate_chunk, jobs):
            store.put_many((key, value, spec_hash, versions) for key, value, versions in records)
            tracker.advance(len(records))
    saved = store.items()
    values = {key: saved[key] for key in points if key in saved}
    return StudyRun(values, computed=len(todo), reused=reused)
