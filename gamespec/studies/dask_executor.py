"""The ``dask`` executor plugin: runs a study's tasks on a Dask ``distributed`` cluster.

With a scheduler address (``--scheduler tcp://host:8786`` or ``GAMESPEC_SCHEDULER``) it connects
to a running cluster; without one it starts a ``distributed.LocalCluster`` of ``workers`` worker
processes with one thread each, for as long as the executor is open. Tasks carry everything they
need (no shared filesystem assumed). A worker that dies is restarted by its nanny and the scheduler
runs its tasks again elsewhere (up to ``distributed.scheduler.allowed-failures`` times per task);
results reach the caller as they finish (``distributed.as_completed``).

A scheduler can run code in its clients: Dask sends results back pickled and the client unpickles
them, so whoever runs the scheduler (or a worker, or sits on the wire) runs code in this process.
Where a study runs is therefore the user's choice (``--scheduler``, ``GAMESPEC_SCHEDULER``, the
API), never a problem file's (:class:`gamespec.studies.point_study.StudyOptions` refuses one), and
a scheduler that is not on this machine is reached only over TLS with a certificate authority that
verifies it (``tls://`` and Dask's ``distributed.comm.tls`` configuration, or a
:class:`distributed.security.Security` given here) or with an explicit ``insecure=True``
(``--insecure-scheduler``) (README, "Security").
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Iterable, Iterator
from typing import Any, Self, TypeVar

from gamespec.errors import GamespecError

LOCAL_HOSTS = frozenset({"localhost"})
"""Host names taken as this machine besides loopback IP addresses (no name is resolved: a DNS
answer is not the user's choice)."""

T = TypeVar("T")
R = TypeVar("R")


class DaskExecutor:
    """A Dask client (and, without an address, the LocalCluster it runs on)."""

    def __init__(
        self,
        workers: int = 1,
        scheduler: str | None = None,
        *,
        security: Any = None,
        insecure: bool = False,
    ) -> None:
        if workers < 1:
            raise ValueError("workers must be at least 1")
        self.scheduler = scheduler
        self.workers = workers
        self.security = security
        self.insecure = insecure
        self._client: Any = None
        self._cluster: Any = None

    @classmethod
    def from_options(cls, workers: int, scheduler: str | None, insecure: bool = False) -> DaskExecutor:
        return cls(workers, scheduler, insecure=insecure)

    def __enter__(self) -> Self:
        if self._client is not None:
            return self
        from distributed import Client, LocalCluster

        if self.scheduler:
            security = connection_security(self.scheduler, self.security, insecure=self.insecure)
            try:
                self._client = Client(self.scheduler, timeout="10s", security=security)
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


def is_local_address(address: str) -> bool:
    """Whether a Dask address is on this machine: ``inproc://``, or ``tcp://``/``tls://`` to a
    loopback IP address or ``localhost``."""
    import ipaddress

    from distributed.comm.addressing import get_address_host, parse_address

    try:
        scheme, _ = parse_address(address)
        if scheme == "inproc":
            return True
        if scheme not in ("tcp", "tls"):
            return False
        host = get_address_host(address).strip("[]")
    except ValueError:
        return False
    if host in LOCAL_HOSTS:
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def connection_security(address: str, security: Any = None, *, insecure: bool = False) -> Any:
    """The :class:`distributed.security.Security` to reach the scheduler at ``address`` with
    (``security``, else Dask's configured one); a GamespecError, before anything connects, when the
    scheduler is not on this machine and neither TLS with a certificate authority (``tls://``, the
    CA that verifies the scheduler's certificate) nor ``insecure`` was chosen: a scheduler runs
    code in its clients (module doc)."""
    from distributed.comm.addressing import parse_address
    from distributed.security import Security

    chosen = security if security is not None else Security()
    if insecure or is_local_address(address):
        return chosen
    try:
        scheme, _ = parse_address(address)
    except ValueError as err:
        raise GamespecError(f"not a Dask scheduler address {address!r}: {err}") from None
    if scheme == "tls" and chosen.tls_ca_file:
        return chosen
    raise GamespecError(
        f"the Dask scheduler at {address} is not on this machine and is not reached over verified TLS: "
        "a scheduler can run code in this process, so use tls:// with Dask's "
        "distributed.comm.tls.ca-file (and client certificate) configured, or pass "
        "--insecure-scheduler if you trust the scheduler and the network to it"
    )
