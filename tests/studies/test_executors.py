"""Executors are plugins; local process workers die with their parent, and a worker that dies
mid-run loses nothing; a Monte Carlo runs through an executor with the serial answer."""

from __future__ import annotations

import signal

import numpy as np
import psutil
import pytest

from gamespec import registry
from gamespec.montecarlo import Normal, Uniform, run, sample
from gamespec.studies.executors import ProcessExecutor, SerialExecutor, executor, ordered_map
from gamespec.studies.runner import run_study
from gamespec.studies.store import ResultStore
from tests.conftest import PROBLEMS
from tests.studies.conftest import start_script, wait_for
from tests.studies.helpers import mean_of_squares, square_or_die_once


def test_executors_are_entry_point_plugins() -> None:
    assert {"serial", "process", "dask"} <= set(registry.names("gamespec.executors"))
    assert isinstance(executor(), SerialExecutor)
    assert isinstance(executor(workers=2), ProcessExecutor)
    assert type(executor(scheduler="tcp://127.0.0.1:1")).__name__ == "DaskExecutor"


def test_unknown_executor_is_exit_2(cli, tmp_path) -> None:
    path = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"
    code, _, err = cli("sweep", path, "--param", "v=0.3", "--out", tmp_path, "--executor", "slurm")
    assert code == 2 and "unknown executor 'slurm'" in err and err.count("\n") == 1


PARENT = """
from gamespec.studies.executors import ProcessExecutor
from tests.studies.helpers import announce_and_sleep
with ProcessExecutor(2) as pool:
    for _ in pool.imap(announce_and_sleep, [120.0, 120.0]):
        pass
"""


def _alive(procs: list[psutil.Process]) -> list[psutil.Process]:
    alive = []
    for proc in procs:
        try:
            if proc.is_running() and proc.status() != psutil.STATUS_ZOMBIE:
                alive.append(proc)
        except psutil.NoSuchProcess:
            continue
    return alive


def test_process_workers_die_with_a_killed_parent() -> None:
    parent = start_script(PARENT)
    workers: list[psutil.Process] = []
    try:
        busy = {int(parent.stdout.readline()) for _ in range(2)}
        workers = psutil.Process(parent.pid).children(recursive=True)
        assert busy <= {w.pid for w in workers}
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        wait_for(lambda: not _alive(workers), timeout=15, what="the workers to die with their parent")
    finally:
        parent.kill()
        for orphan in _alive(workers):
            orphan.kill()
        parent.communicate(timeout=30)


def test_process_worker_killed_mid_run_loses_nothing(tmp_path) -> None:
    points = {f"x={x}": (x, str(tmp_path / "died")) for x in range(10)}
    done = run_study(points, square_or_die_once, ResultStore(tmp_path), executor=ProcessExecutor(2))
    assert (tmp_path / "died").exists()
    assert done.values == {k: x * x for k, (x, _) in points.items()}


def test_monte_carlo_through_an_executor_matches_serial() -> None:
    draws = sample({"x": Normal(1.0, 2.0), "v": Uniform(0.0, 1.0, shape=(2,))}, 40, seed=6)
    serial = run(mean_of_squares, draws, batch_size=40)
    with ProcessExecutor(2) as pool:
        parallel = run(mean_of_squares, draws, batch_size=7, mapper=ordered_map(pool))
    assert all(np.array_equal(serial[k], parallel[k]) for k in serial)


@pytest.mark.parametrize("workers", [1, 2, 5])
def test_chunks_cover_every_point_once(workers) -> None:
    from gamespec.studies.runner import MAX_CHUNK, chunk_size

    for points in (1, 63, 64, 1000, 100_000):
        size = chunk_size(points, workers)
        assert 1 <= size <= MAX_CHUNK
        assert workers > 1 or size == 1


def test_a_worker_compiles_a_spec_once_and_resolves_per_point(tmp_path, monkeypatch) -> None:
    import gamespec.solving
    from gamespec.studies import sweep

    compiled: list[str] = []
    real = gamespec.solving.compile_spec

    def counted(spec, backend=None, options=None):
        compiled.append(spec.name)
        return real(spec, backend, options)

    monkeypatch.setattr(gamespec.solving, "compile_spec", counted)
    monkeypatch.setattr(sweep, "_COMPILED", {})
    path = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"
    run = sweep.sweep(path, [("v", [0.3, 0.4, 0.5, 0.6])], out=tmp_path, show_progress=False)
    assert len(run.values) == 4 and len(compiled) == 1
    for row in run.values.values():
        assert row["t_final"] == pytest.approx((1.0 - 0.001) / (1.0 - row["v"]), abs=1e-6)
