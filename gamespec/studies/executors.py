"""One executor interface for many runs (DESIGN.md, stage 5); executors are plugins.

The entry-point group ``gamespec.executors`` names them: ``serial`` (this process), ``process``
(local processes, here) and ``dask`` (a Dask cluster, :mod:`gamespec.studies.dask_executor`).
``Executor.imap(fn, items)`` yields ``(item, value)`` pairs as runs finish (in any order), so a
study can save each result as soon as it exists; ``fn`` and the items must be picklable outside
:class:`SerialExecutor` (module-level functions, plain data). An executor is a context manager:
its workers live from ``__enter__`` to ``__exit__`` and serve every ``imap`` in between.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Protocol, Self, TypeVar

from gamespec import registry
from gamespec.errors import GamespecError

T = TypeVar("T")
R = TypeVar("R")

GROUP = "gamespec.executors"
SCHEDULER_ENV = "GAMESPEC_SCHEDULER"
"""Environment variable with the address of a Dask scheduler (``--scheduler`` wins over it)."""


class Executor(Protocol):
    """Runs ``fn`` over items and yields ``(item, value)`` as runs complete."""

    workers: int

    def __enter__(self) -> Self: ...

    def __exit__(self, *exc: object) -> None: ...

    def imap(self, fn: Callable[[T], R], items: Iterable[T]) -> Iterator[tuple[T, R]]: ...


class SerialExecutor:
    """Runs in this process, in order."""

    workers = 1

    @classmethod
    def from_options(cls, workers: int, scheduler: str | None, insecure: bool = False) -> SerialExecutor:
        return cls()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def imap(self, fn: Callable[[T], R], items: Iterable[T]) -> Iterator[tuple[T, R]]:
        for item in items:
            yield item, fn(item)


PR_SET_PDEATHSIG = 1
"""``prctl`` option (linux/prctl.h): the signal a process gets when its parent dies."""


def _die_with_parent(parent: int) -> None:
    """Pool-worker initializer: end this worker when the study's process ``parent`` that started
    it dies, even by SIGKILL (which runs no cleanup there): ``PR_SET_PDEATHSIG`` on Linux, a
    watchdog thread that polls ``os.getppid()`` elsewhere; a parent already gone ends it at once."""
    if os.getppid() != parent:
        os._exit(1)
    if sys.platform.startswith("linux"):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
        if os.getppid() != parent:  # it died before prctl took effect
            os._exit(1)
        return

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


class ProcessExecutor:
    """Runs in ``workers`` local processes, keeping ``2 * workers`` runs in flight.

    On Linux, while this process has a single thread, the workers are forked when the executor is
    entered (before a progress bar starts its thread): they inherit the imported modules, so no
    worker pays for importing gamespec and the solvers again. Otherwise they are spawned (a fresh
    interpreter; the main module must then be guarded by ``if __name__ == "__main__"``). A fork
    server is not used: each of its workers holds the server's liveness pipe, so the server and
    the workers would outlive this process. The workers die with this process; a worker that dies
    mid-run (the pool breaks) is replaced and the runs in flight are submitted again, up to
    ``restarts`` times per ``imap``."""

    def __init__(self, workers: int, restarts: int = 3) -> None:
        if workers < 1:
            raise ValueError("workers must be at least 1")
        self.workers = workers
        self.restarts = restarts
        self._pool: ProcessPoolExecutor | None = None

    @classmethod
    def from_options(cls, workers: int, scheduler: str | None, insecure: bool = False) -> ProcessExecutor:
        return cls(workers)

    def _start(self) -> ProcessPoolExecutor:
        forkable = sys.platform.startswith("linux") and threading.active_count() == 1
        context = multiprocessing.get_context("fork" if forkable else "spawn")
        pool = ProcessPoolExecutor(
            self.workers, mp_context=context, initializer=_die_with_parent, initargs=(os.getpid(),)
        )
        pool.submit(os.getpid).result()  # start the workers now, from this thread
        return pool

    def __enter__(self) -> Self:
        if self._pool is None:
            self._pool = self._start()
        return self

    def __exit__(self, *exc: object) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None

    def imap(self, fn: Callable[[T], R], items: Iterable[T]) -> Iterator[tuple[T, R]]:
        owned = self._pool is None
        self.__enter__()
        try:
            yield from self._run(fn, iter(items))
        finally:
            if owned:
                self.__exit__()

    def _run(self, fn: Callable[[T], R], pending: Iterator[T]) -> Iterator[tuple[T, R]]:
        pool = self._pool
        assert pool is not None, "imap enters the executor before it runs"
        running: dict[Future[R], T] = {}
        lost: deque[T] = deque()
        restarts = 0
        while True:
            try:
                while len(running) < 2 * self.workers:
                    item = lost.popleft() if lost else next(pending, _END)
                    if item is _END:
                        break
                    try:
                        running[pool.submit(fn, item)] = item
                    except BrokenProcessPool:
                        lost.appendleft(item)
                        raise
                if not running:
                    return
                done, _ = wait(running, return_when=FIRST_COMPLETED)
                for future in done:
                    value = future.result()
                    yield running.pop(future), value
            except BrokenProcessPool:
                restarts += 1
                if restarts > self.restarts:
                    raise GamespecError(f"local workers died {restarts} times in one run") from None
                lost.extend(running.values())
                running = {}
                pool.shutdown(wait=False, cancel_futures=True)
                self._pool = pool = self._start()


_END: Any = object()


def executor(
    name: str | None = None, workers: int = 1, scheduler: str | None = None, *, insecure: bool = False
) -> Executor:
    """The executor plugin ``name`` for ``workers`` (and a Dask ``scheduler`` address, or the
    ``GAMESPEC_SCHEDULER`` environment variable: the user's choice, never a problem file's).
    Without a name: ``dask`` when a scheduler is given, ``serial`` for one worker, ``process``
    otherwise. ``insecure`` lets the dask executor reach a scheduler on another machine without
    verified TLS (:func:`gamespec.studies.dask_executor.connection_security`)."""
    scheduler = scheduler or os.environ.get(SCHEDULER_ENV) or None
    if name is None:
        name = "dask" if scheduler else ("serial" if workers <= 1 else "process")
    if workers < 1:
        raise GamespecError(f"--workers must be at least 1, got {workers}")
    chosen: Executor = registry.load(GROUP, name).from_options(workers, scheduler, insecure)
    return chosen


def ordered_map(runner: Executor) -> Callable[[Callable[[T], R], Sequence[T]], list[R]]:
    """``map(fn, items)`` through ``runner``, values back in item order (a Monte Carlo mapper,
    :data:`gamespec.montecarlo.Mapper`)."""

    def mapped(fn: Callable[[T], R], items: Sequence[T]) -> list[R]:
        values: list[Any] = [None] * len(items)
        jobs = [(fn, i, item) for i, item in enumerate(items)]
        for (_fn, i, _item), value in runner.imap(_call_indexed, jobs):
            values[i] = value
        return values

    return mapped


def _call_indexed(job: tuple[Callable[[Any], Any], int, Any]) -> Any:
    fn, _index, item = job
    return fn(item)
