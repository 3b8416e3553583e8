"""A hostile Dask scheduler cannot reach anyone through a problem file (README, "Security").

The cluster here is real (a scheduler on 127.0.0.1 and one worker process) and hostile: the
worker's preload replaces the study runner's task function by one whose result unpickles, in the
client, into a shell command that writes the client's process id to a marker file. A problem file
that names this scheduler is refused at load and nothing connects (no marker, no client on the
scheduler); the same scheduler given by the user (the API, as ``--scheduler`` does) is reached and
does run code in the client, which is why the choice is the user's alone. A scheduler on another
machine is refused before connecting unless the user opts in or uses verified TLS.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from gamespec.errors import GamespecError, SpecError
from gamespec.loader import load
from gamespec.studies.dask_executor import DaskExecutor, connection_security, is_local_address
from gamespec.studies.runner import run_study
from gamespec.studies.store import ResultStore
from tests.conftest import PROBLEMS

STUDY_FILES = {
    "study": PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml",
    "rcs_study": PROBLEMS / "ch6" / "rcs_multi_obstacle_study.yaml",
}

HOSTILE_PRELOAD = """
import os
from gamespec.studies import runner

class Payload:
    def __reduce__(self):
        return (os.system, ("echo $PPID > {marker}",))

def hostile_chunk(job):
    return [(key, Payload(), {{}}) for key, _ in job[1]]

runner._evaluate_chunk = hostile_chunk
"""


@pytest.fixture(scope="module")
def hostile(tmp_path_factory) -> Iterator[tuple[str, Path, object]]:
    """(address, marker file, scheduler) of the hostile cluster."""
    from distributed import LocalCluster

    marker = tmp_path_factory.mktemp("hostile") / "marker"
    with LocalCluster(
        n_workers=1,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=logging.ERROR,
        preload=[HOSTILE_PRELOAD.format(marker=marker)],
    ) as cluster:
        yield cluster.scheduler_address, marker, cluster.scheduler


def _clients(scheduler) -> set[str]:
    return {name for name in scheduler.clients if name != "fire-and-forget"}


@pytest.mark.parametrize("backend", sorted(STUDY_FILES))
def test_a_file_naming_the_scheduler_is_refused_and_nothing_connects(
    backend, hostile, tmp_path, monkeypatch
) -> None:
    address, marker, scheduler = hostile
    monkeypatch.delenv("GAMESPEC_SCHEDULER", raising=False)
    before = _clients(scheduler)
    document = yaml.safe_load(STUDY_FILES[backend].read_text())
    document["store"] = str(tmp_path / "points")
    document["solver"] = {
        "backend": backend,
        "options": {backend: {"executor": "dask", "scheduler": address}},
    }
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(document))
    with pytest.raises(SpecError) as refused:
        load(path)
    assert refused.value.field == f"solver.options.{backend}.scheduler"
    assert "--scheduler" in refused.value.reason
    time.sleep(0.2)
    assert not marker.exists()
    assert _clients(scheduler) == before


def test_the_cli_refuses_the_file_route_with_one_line(cli, hostile, tmp_path) -> None:
    address, marker, _ = hostile
    study = STUDY_FILES["study"]
    code, _, err = cli("solve", study, "--set", f"solver.options.study.scheduler={address}")
    assert code == 2
    assert err.count("\n") == 1 and "solver.options.study.scheduler" in err
    assert not marker.exists()


def test_the_users_choice_connects_and_shows_why_it_must_be_the_users(hostile, tmp_path) -> None:
    address, marker, _ = hostile
    marker.unlink(missing_ok=True)
    run_study({"a": 1}, abs, ResultStore(tmp_path), executor=DaskExecutor(scheduler=address))
    assert marker.read_text().strip() == str(os.getpid())
    marker.unlink()


@pytest.mark.parametrize("address", ["tcp://10.255.255.1:8786", "192.0.2.7:8786", "tls://example.org:8786"])
def test_a_scheduler_elsewhere_needs_verified_tls_or_an_opt_in(address) -> None:
    assert not is_local_address(address)
    with pytest.raises(GamespecError, match="--insecure-scheduler"):
        DaskExecutor(scheduler=address).__enter__()
    assert connection_security(address, insecure=True) is not None


def test_a_tls_scheduler_with_a_certificate_authority_is_accepted() -> None:
    from distributed.security import Security

    security = Security(tls_ca_file=__file__, require_encryption=True)
    assert connection_security("tls://10.255.255.1:8786", security) is security


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:8786", "localhost:8786", "tls://[::1]:8786"])
def test_local_addresses(address) -> None:
    assert is_local_address(address)
