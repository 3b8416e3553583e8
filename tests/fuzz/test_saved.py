"""Fuzzing saved inputs (README, "Security"): tampered Result folders through ``gamespec plot``,
``Result.load`` and ``guess: {result: DIR}``, and tampered study stores through ``gamespec
results``, ``gamespec plot`` and a resumed ``gamespec sweep``. Every input keeps the bad-input
promise (:mod:`tests.fuzz.harness`) within the CPU-time bound, with no traceback, and no input
grows the memory of the process by more than :data:`MEMORY_GROWTH_BYTES`. A FIFO ``result.json``
is answered within a second."""

from __future__ import annotations

import json
import os
import re
import resource
import shutil
import tempfile
import zipfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gamespec.errors import GamespecError
from gamespec.limits import MAX_ARRAY_VALUES
from gamespec.result import Result
from tests.conftest import PROBLEMS
from tests.fuzz.harness import TIME_BOUND_S, assert_promise, cpu_bound, run_cli
from tests.fuzz.saved import (
    RESULTS,
    STORES,
    _members,
    _npy,
    _write_members,
    result_tampering,
    store_tampering,
)

pytestmark = pytest.mark.skipif(not RESULTS or not STORES, reason="no seeds: python -m tests.fuzz.make_saved")

MEMORY_GROWTH_BYTES = 8 * MAX_ARRAY_VALUES
"""Most a tampered input may add to the process's peak memory: one array of the largest size a
saved Result may hold (an input claiming more is refused before anything is allocated)."""

ANIMATION_BOUND_S = 12 * TIME_BOUND_S
"""CPU seconds a ``plot --animate`` may take: an animation draws up to 60 frames (a shipped
scenario's takes about 20 s of CPU on an idle core), each more than a still figure."""

LONG = os.environ.get("HYPOTHESIS_PROFILE") == "long"


def examples(fast: int) -> int:
    """Inputs per test: ``fast`` in the default profile (a few seconds in all), 25 times as many
    in the long one."""
    return 25 * fast if LONG else fast


SWEPT = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"
"""The problem of the ``optimal_control`` seed (a guess from it fits) and of the sweep seed."""


def _peak_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


@contextmanager
def _copy(seed: Path) -> Iterator[Path]:
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch) / seed.name
        shutil.copytree(seed, folder)
        yield folder


def _check(args: list[object], folder: Path, *, reports: bool = False, bound_s: float = TIME_BOUND_S) -> None:
    """The promise for one run on a tampered ``folder`` within ``bound_s`` of CPU time;
    ``reports``: a store's damaged-record lines (and ``wrote FILE``) may come with a successful
    answer on stderr."""
    before = _peak_bytes()
    outcome = run_cli([str(a) for a in args], bound_s=bound_s)
    assert _peak_bytes() - before < MEMORY_GROWTH_BYTES, outcome
    if reports and outcome.code == 0:
        assert all(
            line.startswith((str(folder), "wrote ", "resuming: ")) for line in outcome.err.splitlines()
        ), outcome
        return
    assert_promise(outcome, "")
    assert "Traceback" not in outcome.err, outcome


@settings(max_examples=examples(12))
@given(
    seed=st.sampled_from(RESULTS),
    tampering=result_tampering(),
    animate=st.integers(0, 9).map(lambda n: LONG and n == 0),
)
def test_tampered_result_folders_plot(seed: Path, tampering, animate: bool) -> None:
    """A tenth of the long profile's plots are animations (seconds of CPU each; none in the fast one)."""
    _, tamper = tampering
    with _copy(seed) as folder:
        tamper(folder)
        flags = ["--animate"] if animate else []
        bound = ANIMATION_BOUND_S if animate else TIME_BOUND_S
        _check(["plot", folder, "--out", folder.parent / "figures", *flags], folder, bound_s=bound)


@settings(max_examples=examples(25))
@given(seed=st.sampled_from(RESULTS), tampering=result_tampering())
def test_tampered_result_folders_load(seed: Path, tampering) -> None:
    _, tamper = tampering
    with _copy(seed) as folder:
        tamper(folder)
        before = _peak_bytes()
        try:
            Result.load(folder)
        except GamespecError as err:
            assert "\n" not in str(err)
        assert _peak_bytes() - before < MEMORY_GROWTH_BYTES


@settings(max_examples=examples(4))
@given(tampering=result_tampering())
def test_tampered_result_as_a_guess(tampering) -> None:
    _, tamper = tampering
    seed = next(r for r in RESULTS if r.name == "optimal_control")
    with _copy(seed) as folder:
        tamper(folder)
        _check(["solve", SWEPT, "--set", f"guess.result={folder}"], folder)


@settings(max_examples=examples(12))
@given(
    seed=st.sampled_from(STORES),
    tampering=store_tampering(),
    command=st.sampled_from(["results", "results --csv", "results --json", "plot"]),
)
def test_tampered_study_stores(seed: Path, tampering, command: str) -> None:
    _, tamper = tampering
    with _copy(seed) as folder:
        tamper(folder)
        name, *flags = command.split()
        extra = [folder.parent / "table.csv"] if flags == ["--csv"] else []
        out = ["--out", folder.parent / "figures"] if name == "plot" else []
        _check([name, folder, *flags, *extra, *out], folder, reports=True)


@settings(max_examples=examples(3))
@given(tampering=store_tampering())
def test_tampered_sweep_store_resumes(tampering) -> None:
    _, tamper = tampering
    seed = next(s for s in STORES if s.name == "sweep")
    with _copy(seed) as folder:
        tamper(folder)
        grid = ["--param", "v=0.3,0.5", "--param", "u=1,1.5"]
        _check(["sweep", SWEPT, *grid, "--out", folder, "--json"], folder, reports=True)


def test_a_fifo_result_json_is_refused_without_blocking(tmp_path) -> None:
    """A FIFO uses no CPU while it blocks, so a CPU bound alone cannot see it: the bound's idle
    window (a second in which the load used under 1 % of it in CPU time) does; the answer takes
    microseconds of work."""
    folder = tmp_path / "fifo"
    shutil.copytree(RESULTS[0], folder)
    (folder / "result.json").unlink()
    os.mkfifo(folder / "result.json")
    with cpu_bound(TIME_BOUND_S, idle_window=1.0), pytest.raises(GamespecError, match="not a regular file"):
        Result.load(folder)


def _json_edit(edit):
    def tamper(folder: Path) -> None:
        document = json.loads((folder / "result.json").read_text())
        edit(document)
        (folder / "result.json").write_text(json.dumps(document))

    return tamper


def _npy_member(header: str, data: bytes = b"") -> Callable[[Path], None]:
    def tamper(folder: Path) -> None:
        with zipfile.ZipFile(folder / "arrays.npz", "w") as archive:
            archive.writestr("time.npy", _npy(header, data))

    return tamper


def _without_member(name: str) -> Callable[[Path], None]:
    def tamper(folder: Path) -> None:
        members = _members(folder / "arrays.npz")
        del members[name]
        _write_members(folder / "arrays.npz", members)

    return tamper


ISSUE_CASES = {
    "a symlink to /dev/zero": ("optimal_control", lambda f: _replace_by_link(f, "/dev/zero"), "leads out"),
    "a header claiming 10**15 values": (
        "optimal_control",
        _npy_member("{'descr': '<f8', 'fortran_order': False, 'shape': (1000000000000000,), }"),
        "MAX_ARRAY_VALUES",
    ),
    "a zero dimension beside huge ones (found by the fuzz)": (
        "optimal_control",
        _npy_member(
            "{'descr': '<f8', 'fortran_order': False, 'shape': (0, 10000000000000000, 10000000000000000), }"
        ),
        "MAX_ARRAY_VALUES",
    ),
    "a header holding code": (
        "optimal_control",
        _npy_member("{'descr': __import__('os').getcwd(), 'fortran_order': False, 'shape': (3,), }"),
        "not a plain array",
    ),
    "an object dtype": (
        "optimal_control",
        _npy_member("{'descr': '|O', 'fortran_order': False, 'shape': (1,), }", b"\0" * 8),
        "not a plain array",
    ),
    "engagement.pursuers.1 = []": (
        "engagement",
        _json_edit(lambda d: d["metrics"]["engagement"]["pursuers"].__setitem__(1, [])),
        "metrics.engagement.pursuers.1",
    ),
    "figure.obstacle_radius = 'abc'": (
        "differential_game",
        _json_edit(lambda d: d["metrics"]["figure"].__setitem__("obstacle_radius", "abc")),
        "metrics.figure.obstacle_radius",
    ),
    "a scenario read as a differential game": (
        "pursuit_scenario",
        _json_edit(lambda d: d.__setitem__("kind", "differential_game")),
        "states.pursuers",
    ),
    "a scenario without its time grid (found by the long fuzz)": (
        "pursuit_scenario",
        _without_member("time.npy"),
        "no time grid",
    ),
    "allocation_history.2.assignment.2 = '0'": (
        "pursuit_scenario",
        _json_edit(lambda d: d["metrics"]["allocation_history"][2]["assignment"].__setitem__(2, "0")),
        None,
    ),
}
"""The tampered folders issue 27 names (and one the fuzz found), with what the one line must say
(None: the folder is still a Result its readers can draw, so it plots)."""


def _replace_by_link(folder: Path, target: str) -> None:
    (folder / "result.json").unlink()
    (folder / "result.json").symlink_to(target)


@pytest.mark.parametrize("case", sorted(ISSUE_CASES))
def test_the_folders_issue_27_names(case: str) -> None:
    seed_name, tamper, needle = ISSUE_CASES[case]
    with _copy(next(r for r in RESULTS if r.name == seed_name)) as folder:
        tamper(folder)
        if needle is None:
            assert Result.load(folder).kind == "pursuit_scenario"
            return
        with pytest.raises(GamespecError, match=re.escape(needle)) as refused:
            Result.load(folder)
        assert "\n" not in str(refused.value)


@pytest.mark.slow
def test_the_animated_scenario_of_issue_27_ends_within_its_bound() -> None:
    _, tamper, _ = ISSUE_CASES["allocation_history.2.assignment.2 = '0'"]
    with _copy(next(r for r in RESULTS if r.name == "pursuit_scenario")) as folder:
        tamper(folder)
        _check(["plot", folder, "--out", folder.parent / "f", "--animate"], folder, bound_s=ANIMATION_BOUND_S)


@pytest.mark.parametrize("seed_name", ["sweep", "table_2_1"])
def test_a_point_of_the_wrong_shape_is_reported_and_left_out(seed_name: str) -> None:
    import sqlite3

    from gamespec.studies.store import _digest

    with _copy(next(s for s in STORES if s.name == seed_name)) as folder:
        db = sqlite3.connect(folder / "store.sqlite", isolation_level=None)
        (count,) = db.execute("SELECT count(*) FROM points").fetchone()
        (key,) = db.execute("SELECT key FROM points LIMIT 1").fetchone()
        db.execute("UPDATE points SET value = '[]', digest = ? WHERE key = ?", (_digest("[]"), key))
        db.close()
        table = run_cli(["results", folder, "--json"])
        assert table.code == 0 and len(json.loads(table.out)) == count - 1
        assert table.err.strip().splitlines() == [
            f"{folder / 'store.sqlite'}: record {key!r} is damaged "
            "(a sweep point is list, not a mapping); computing it again"
        ]
        figures = run_cli(["plot", folder, "--out", folder.parent / "figures"])
        assert figures.code == 0, figures


def test_a_parameter_name_cannot_write_a_figure_out_of_its_folder() -> None:
    import sqlite3

    with _copy(next(s for s in STORES if s.name == "sweep")) as folder:
        db = sqlite3.connect(folder / "store.sqlite", isolation_level=None)
        meta = json.dumps({"type": "sweep", "problem": "p", "parameters": ["../../escaped", "u"]})
        db.execute("INSERT OR REPLACE INTO meta VALUES ('study', ?)", (meta,))
        db.close()
        outcome = run_cli(["plot", folder, "--out", folder / "figures"])
        assert outcome.code == 2 and "meta:study" in outcome.err, outcome
        assert not list(folder.parent.glob("*escaped*")) and not list(folder.parent.parent.glob("*escaped*"))
