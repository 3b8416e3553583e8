"""The ``dask`` executor plugin: runs a study's tasks on a Dask ``distributed`` cluster.

With a scheduler address (``--scheduler tcp://host:8786`` or ``GAMESPEC_SCHEDULER``) it connects
to a running cluster; without one it starts a ``distributed.LocalCluster`` of ``workers`` worker
processes with one thread each, for as long as the executor is open. Tasks carry everything they
need (no shared filesystem assumed). A worker that dies is restarted by its nanny and the scheduler
runs its tasks again elsewhere (up to ``distributed.scheduler.allowed-failures`` times per task);
results reach the caller as they finish (``distributed.as_completed``).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Iterator
from typing import Any, Self, TypeVar

from gamespec.errors import GamespecError

T = TypeVar("T")
R = TypeVar("R")


class DaskExecutor:
    """A Dask client (and, without an address, the LocalCluster it runs on)."""

    def __init__(self, workers: int = 1, scheduler: str | None = None) -> None:
        if workers < 1:
            raise ValueError("workers must be at least 1")
        self.scheduler = scheduler
        self.workers = workers
        self._client: Any = None
        self._cluster: Any = None

    @classmethod
    def from_options(cls, workers: int, scheduler: str | None) -> DaskExecutor:
        return cls(workers, scheduler)

    def __enter__(self) -> Self:
        if self._client is not None:
            return self
        from distributed import Client, LocalCluster

        if self.scheduler:
            try:
                self._client = Client(self.scheduler, timeout="10s")
            except (OSError, TimeoutError) as err:
                raise GamespecError(f"cannot reach the Dask scheduler at {self.scheduler}: {err}") from None
            self.workers = max(1, sum(self._client.nthreads().values()))
        else:
            self._cluster = LocalCluster(
                n_workers=self.workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=logging.ERROR,
            )
            self._client = Client(self._cluster)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._client is not None:
            self._client.close()
            self._client = None
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None

    def imap(self, fn: Callable[[T], R], items: Iterable[T]) -> Iterator[tuple[T, R]]:
        owned = self._client is None
        self.__enter__()
        try:
            yield from self._run(fn, items)
        finally:
            if owned:
                self.__exit__()

    def _run(self, fn: Callable[[T], R], items: Iterable[T]) -> Iterator[tuple[T, R]]:
        from distributed import as_completed
        from distributed.scheduler import KilledWorker

        futures = {self._client.submit(fn, item, pure=False): item for item in items}
        try:
            for future in as_completed(futures):
                item = futures.pop(future)
                try:
                    value = future.result()
                except KilledWorker as err:
                    raise GamespecError(f"a task killed its Dask worker too often: {err}") from None
                future.release()
                yield item, value
        finally:
            for future in futures:
                future.cancel()
