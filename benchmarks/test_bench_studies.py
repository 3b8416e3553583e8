"""Study execution speed: per-task overhead of each executor, and the Table 2.1 study on one and
two workers.

Run: ``python -m pytest benchmarks/test_bench_studies.py --benchmark-enable -m "slow or not slow"``.

- ``test_per_task_overhead``: 200 tasks that do nothing through ``Executor.imap`` (one task each,
  no chunking), workers started before timing; the wall time per task is the executor's
  overhead (pickling, scheduling, a round trip). Reported in ``extra_info`` with its ratio to
  serial.
- ``test_table_2_1_speedup`` (slow): the reduced Table 2.1 study (3 speeds, 8 × 4 grid, 96 points)
  as a user runs it, ``gamespec pursuit study`` in a fresh process, serially and on 2 local
  workers, from empty stores. The wall-clock speedup depends on how many idle cores the machine
  has, so what is asserted is the work the parallel path adds: the CPU time of the serial run over
  that of the parallel one (parent and workers) must be at least 0.9, i.e. a speedup of at least
  1.8 on two free cores; the wall-clock speedup is reported beside it.
"""

from __future__ import annotations

import resource
import subprocess
import sys
import time
from pathlib import Path

import pytest

from gamespec.studies.dask_executor import DaskExecutor
from gamespec.studies.executors import ProcessExecutor, SerialExecutor
from tests.conftest import PROBLEMS
from tests.studies.helpers import square

TASKS = 200
STUDY = PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml"
REDUCED = ["speeds=[0.3,0.5,0.7]", "grid.angles=8", "grid.fractions=4"]

_serial_per_task: dict[str, float] = {}


def _through(executor) -> float:
    tic = time.perf_counter()
    done = sum(1 for _ in executor.imap(square, range(TASKS)))
    assert done == TASKS
    return (time.perf_counter() - tic) / TASKS


@pytest.mark.parametrize("name", ["serial", "process", "dask"])
def test_per_task_overhead(benchmark, name: str) -> None:
    make = {"serial": SerialExecutor, "process": lambda: ProcessExecutor(2), "dask": lambda: DaskExecutor(2)}
    benchmark.group = "per-task overhead"
    with make[name]() as executor:
        _through(executor)  # warm: workers started, modules imported
        per_task = benchmark.pedantic(_through, args=(executor,), rounds=3)
    _serial_per_task.setdefault(name, per_task)
    benchmark.extra_info["per_task_ms"] = 1e3 * per_task
    if "serial" in _serial_per_task:
        benchmark.extra_info["ratio_to_serial"] = per_task / _serial_per_task["serial"]


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _study(folder, workers: int) -> tuple[float, float]:
    """Wall and CPU time (the command and every worker it waited for) of one study run."""
    overrides = [arg for item in [*REDUCED, f"store={folder}"] for arg in ("--set", item)]
    command = [str(Path(sys.executable).parent / "gamespec"), "pursuit", "study", str(STUDY), *overrides]
    cpu, tic = _children_cpu(), time.perf_counter()
    subprocess.run([*command, "--workers", str(workers), "--json"], check=True, capture_output=True)
    return time.perf_counter() - tic, _children_cpu() - cpu


@pytest.mark.slow
def test_table_2_1_speedup(benchmark, tmp_path) -> None:
    benchmark.group = "Table 2.1 (reduced)"
    serial_wall, serial_cpu = _study(tmp_path / "serial", 1)
    wall, cpu = benchmark.pedantic(_study, args=(tmp_path / "two", 2), rounds=1, iterations=1)
    benchmark.extra_info.update(
        serial_wall_s=serial_wall,
        two_worker_wall_s=wall,
        wall_speedup=serial_wall / wall,
        cpu_efficiency=serial_cpu / cpu,
    )
    assert serial_cpu / cpu >= 0.9, f"serial {serial_cpu:.2f} s CPU, two workers {cpu:.2f} s CPU"
