"""The study store survives faults: records are durable rows of one SQLite file, a damaged record
is reported and computed again, an unreadable file is moved aside, and a bad --out is exit 2."""

from __future__ import annotations

import sqlite3

import pytest

from gamespec.studies.runner import run_study
from gamespec.studies.store import FILENAME, ResultStore
from tests.conftest import PROBLEMS
from tests.studies.helpers import square

POINTS = {f"x={x}": x for x in range(8)}
SWEEP = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"


def test_values_and_provenance_round_trip(tmp_path) -> None:
    store = ResultStore(tmp_path)
    store.put("a", {"t": 1.5, "nested": [1, 2]}, spec_hash="abc", versions={"numpy": "2"})
    again = ResultStore(tmp_path)
    assert again.items() == {"a": {"t": 1.5, "nested": [1, 2]}}
    provenance = again.provenance()["a"]
    assert provenance["spec_hash"] == "abc" and provenance["versions"] == {"numpy": "2"}
    assert again.meta("study") is None


def test_many_points_are_rows_of_one_file(tmp_path) -> None:
    store = ResultStore(tmp_path)
    for start in range(0, 100_000, 20_000):
        store.put_many((f"p{i}", i, None, None) for i in range(start, start + 20_000))
    assert len(store.done()) == 100_000
    assert {p.name for p in tmp_path.iterdir()} <= {FILENAME, FILENAME + "-wal", FILENAME + "-shm"}


def test_run_study_stores_provenance_of_the_worker(tmp_path) -> None:
    run = run_study(POINTS, square, ResultStore(tmp_path), show_progress=False, spec_hash="h1")
    assert run.values == {k: x * x for k, x in POINTS.items()}
    assert (run.computed, run.reused) == (8, 0)
    provenance = ResultStore(tmp_path).provenance()
    assert all(p["spec_hash"] == "h1" and "numpy" in p["versions"] for p in provenance.values())


def _truncate(folder, key: str) -> None:
    with sqlite3.connect(folder / FILENAME) as db:
        db.execute("UPDATE points SET value = substr(value, 1, length(value) / 2) WHERE key = ?", (key,))


def test_truncated_record_is_reported_and_recomputed(tmp_path) -> None:
    run_study({"x=12": 12, "x=3": 3}, square, ResultStore(tmp_path), show_progress=False)
    _truncate(tmp_path, "x=12")
    lines: list[str] = []
    run = run_study(
        {"x=12": 12, "x=3": 3}, square, ResultStore(tmp_path), show_progress=False, report=lines.append
    )
    assert run.values == {"x=12": 144, "x=3": 9}
    assert (run.computed, run.reused) == (1, 1)
    assert any("'x=12' is damaged" in line for line in lines)
    assert any("resuming: 1 of 2 points reused" in line for line in lines)
    assert ResultStore(tmp_path).damaged == []


def test_unreadable_store_file_is_moved_aside(tmp_path) -> None:
    run_study(POINTS, square, ResultStore(tmp_path), show_progress=False)
    for suffix in ("-wal", "-shm"):
        (tmp_path / (FILENAME + suffix)).unlink(missing_ok=True)
    (tmp_path / FILENAME).write_bytes(b"not a database, half a page of garbage" * 20)
    lines: list[str] = []
    run = run_study(POINTS, square, ResultStore(tmp_path), show_progress=False, report=lines.append)
    assert run.values == {k: x * x for k, x in POINTS.items()} and run.computed == len(POINTS)
    assert any("unreadable" in line for line in lines)
    assert len(list(tmp_path.glob(FILENAME + ".damaged-*"))) == 1


def test_rerun_says_it_resumed(cli, tmp_path) -> None:
    code, _, err = cli("sweep", SWEEP, "--param", "v=0.3,0.5", "--out", tmp_path)
    assert code == 0, err
    code, _, err = cli("sweep", SWEEP, "--param", "v=0.3,0.5,0.6", "--out", tmp_path)
    assert code == 0, err
    assert "resuming: 2 of 3 points reused" in err
    assert "(1 computed now, 2 reused)" in err


@pytest.mark.parametrize("where", ["file", "below_a_file"])
def test_out_that_cannot_hold_a_store_is_exit_2(cli, tmp_path, where) -> None:
    afile = tmp_path / "taken"
    afile.write_text("x")
    out = afile if where == "file" else afile / "sub"
    code, _, err = cli("sweep", SWEEP, "--param", "v=0.3", "--out", out)
    assert code == 2
    assert err.count("\n") == 1 and str(out) in err and "Traceback" not in err
