"""One executor interface for many runs (DESIGN.md, stage 5): serial, or local processes.

``Executor.imap(fn, items)`` yields ``(item, value)`` pairs as runs finish (in any order), so a
study can save each result as soon as it exists. ``fn`` and the items must be picklable for
:class:`ProcessExecutor` (module-level functions, plain data).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Protocol, TypeVar

T = TypeVar("T")
R = TypeVar("R")


class Executor(Protocol):
    """Runs ``fn`` over items and yields results as they complete."""

    def imap(self, fn: Callable[[T], R], items: Iterable[T]) -> Iterator[tuple[T, R]]: ...


class SerialExecutor:
    """Runs in this process, in order."""

    def imap(self, fn: Callable[[T], R], items: Iterable[T]) -> Iterator[tuple[T, R]]:
        for item in items:
            yield item, fn(item)


class ProcessExecutor:
    """Runs in ``workers`` local processes, keeping at most ``2 * workers`` runs in flight."""

    def __init__(self, workers: int) -> None:
        if workers < 1:
            raise ValueError("workers must be at least 1")
        self.workers = workers

    def imap(self, fn: Callable[[T], R], items: Iterable[T]) -> Iterator[tuple[T, R]]:
        pending = iter(items)
        with ProcessPoolExecutor(self.workers) as pool:
            running = {}
            for item in pending:
                running[pool.submit(fn, item)] = item
                if len(running) >= 2 * self.workers:
                    break
            while running:
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                for future in done:
                    item = running.pop(future)
                    yield item, future.result()
                    nxt = next(pending, None)
                    if nxt is not None:
                        running[pool.submit(fn, nxt)] = nxt


def executor(workers: int = 1) -> Executor:
    """Serial for one worker, local processes otherwise."""
    return SerialExecutor() if workers <= 1 else ProcessExecutor(workers)
