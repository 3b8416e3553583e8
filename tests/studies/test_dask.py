"""The dask executor on a real LocalCluster (2 worker processes, one per module): a sweep and the
Table 2.1 study give the serial results, a worker killed mid-run loses nothing, a killed client
resumes, and a Monte Carlo runs through it."""

from __future__ import annotations

import json
import signal

import numpy as np
import pytest

from gamespec.montecarlo import Normal, Uniform, run, sample
from gamespec.studies.dask_executor import DaskExecutor
from gamespec.studies.executors import ordered_map
from gamespec.studies.runner import run_study
from gamespec.studies.store import ResultStore
from tests.conftest import PROBLEMS
from tests.studies.conftest import start_script, stored_keys, wait_for
from tests.studies.helpers import mean_of_squares, slow_square, square_or_die_once

SWEEP = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"
STUDY = PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml"
TINY = ["--set", "speeds=[0.4,0.6]", "--set", "grid.angles=2", "--set", "grid.fractions=2"]

SOLVER_RTOL = 1e-7
"""Relative agreement of two solves of one point (IPOPT's tolerance 1e-8 on a scaled problem;
the workers warm-start from different previous points)."""


def test_sweep_on_the_cluster_matches_serial(cli, tmp_path, scheduler) -> None:
    grid = ("--param", "v=0.3:0.6:4", "--param", "u=1,1.5", "--json")
    code, serial, err = cli("sweep", SWEEP, *grid, "--out", tmp_path / "serial")
    assert code == 0, err
    code, dask, err = cli("sweep", SWEEP, *grid, "--out", tmp_path / "dask", "--scheduler", scheduler)
    assert code == 0, err
    serial_rows, dask_rows = json.loads(serial), json.loads(dask)
    assert len(serial_rows) == len(dask_rows) == 8
    for a, b in zip(serial_rows, dask_rows, strict=True):
        assert (a["v"], a["u"], a["status"]) == (b["v"], b["u"], b["status"])
        assert b["t_final"] == pytest.approx(a["t_final"], rel=SOLVER_RTOL)
    hashes = {p["spec_hash"] for p in ResultStore(tmp_path / "dask").provenance().values()}
    assert hashes == {p["spec_hash"] for p in ResultStore(tmp_path / "serial").provenance().values()}
    assert len(hashes) == 1


def test_table_2_1_study_on_the_cluster_matches_serial(cli, tmp_path, scheduler) -> None:
    def solve(*extra: str) -> dict:
        code, out, err = cli("solve", STUDY, *TINY, *extra, "--json")
        assert code == 0, err
        return json.loads(out)

    serial = solve("--set", f"store={tmp_path / 'serial'}")
    dask = solve("--set", f"store={tmp_path / 'dask'}", "--scheduler", scheduler)
    assert serial["metrics"]["points"] == dask["metrics"]["points"] == dask["metrics"]["computed"] == 8
    # the suboptimal heading is a closed-form simulation: bit for bit the same in any process
    assert dask["arrays"]["t_suboptimal"] == serial["arrays"]["t_suboptimal"]
    np.testing.assert_allclose(dask["arrays"]["t_optimal"], serial["arrays"]["t_optimal"], rtol=SOLVER_RTOL)


def test_worker_killed_mid_run_loses_nothing(tmp_path, scheduler) -> None:
    points = {f"x={x}": (x, str(tmp_path / "died")) for x in range(12)}
    done = run_study(
        points, square_or_die_once, ResultStore(tmp_path), executor=DaskExecutor(scheduler=scheduler)
    )
    assert (tmp_path / "died").exists()
    assert done.values == {k: x * x for k, (x, _) in points.items()}


CLIENT = """
import sys
from gamespec.studies.dask_executor import DaskExecutor
from gamespec.studies.runner import run_study
from gamespec.studies.store import ResultStore
from tests.studies.helpers import slow_square
points = {f"x={x}": x for x in range(40)}
run_study(points, slow_square, ResultStore(sys.argv[1]), executor=DaskExecutor(scheduler=sys.argv[2]),
          show_progress=False)
"""


def test_killed_client_resumes_on_a_rerun(tmp_path, scheduler) -> None:
    client = start_script(CLIENT, str(tmp_path), scheduler)
    try:
        wait_for(lambda: len(stored_keys(tmp_path)) >= 4, what="a few points in the store")
    finally:
        client.send_signal(signal.SIGKILL)
        client.communicate(timeout=30)
    saved = stored_keys(tmp_path)
    assert 4 <= len(saved) < 40
    lines: list[str] = []
    points = {f"x={x}": x for x in range(40)}
    cluster = DaskExecutor(scheduler=scheduler)
    again = run_study(points, slow_square, ResultStore(tmp_path), executor=cluster, report=lines.append)
    assert again.values == {k: x * x for k, x in points.items()}
    assert again.reused == len(saved) and again.computed == 40 - len(saved)
    assert f"resuming: {len(saved)} of 40 points reused" in lines[-1]


def test_monte_carlo_on_the_cluster_matches_serial(scheduler) -> None:
    dists = {"x": Normal(0.0, 3.0), "v": Uniform(-1.0, 1.0, shape=(3,))}
    draws = sample(dists, 30, seed=2, method="latin_hypercube")
    serial = run(mean_of_squares, draws, batch_size=30)
    with DaskExecutor(scheduler=scheduler) as cluster:
        parallel = run(mean_of_squares, draws, batch_size=4, mapper=ordered_map(cluster))
    assert all(np.array_equal(serial[k], parallel[k]) for k in serial)
