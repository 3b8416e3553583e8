"""Studies: results stream into the store as they finish, and an interrupted study resumes."""

from __future__ import annotations

import pytest

from gamespec.studies.executors import ProcessExecutor, SerialExecutor
from gamespec.studies.runner import run_study
from gamespec.studies.store import ResultStore

POINTS = {f"x={x}": x for x in range(6)}


def square(x: int) -> int:
    return x * x


def square_but_fail_on_four(x: int) -> int:
    if x == 4:
        raise RuntimeError("interrupted")
    return x * x


@pytest.mark.parametrize("runner", [SerialExecutor(), ProcessExecutor(2)])
def test_every_point_is_stored(tmp_path, runner) -> None:
    values = run_study(POINTS, square, ResultStore(tmp_path), executor=runner, show_progress=False).values
    assert values == {k: x * x for k, x in POINTS.items()}
    assert ResultStore(tmp_path).items() == values


def test_interrupted_study_resumes_without_redoing_points(tmp_path) -> None:
    store = ResultStore(tmp_path)
    with pytest.raises(RuntimeError, match="interrupted"):
        run_study(POINTS, square_but_fail_on_four, store, show_progress=False)
    assert store.done() == {"x=0", "x=1", "x=2", "x=3"}
    calls: list[int] = []

    def counted(x: int) -> int:
        calls.append(x)
        return x * x

    values = run_study(POINTS, counted, store, show_progress=False).values
    assert sorted(calls) == [4, 5]
    assert values == {k: x * x for k, x in POINTS.items()}


def test_sweep_matches_the_closed_form_and_resumes(cli, tmp_path) -> None:
    import json

    from tests.conftest import PROBLEMS

    path = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"
    args = ("sweep", path, "--param", "v=0.3:0.6:3", "--param", "u=1,1.5", "--out", tmp_path, "--json")
    code, out, _ = cli(*args)
    rows = json.loads(out)
    assert code == 0 and len(rows) == 6
    for row in rows:
        assert row["t_final"] == pytest.approx((1.0 - 0.001) / (row["u"] - row["v"]), abs=1e-6)
    code, again, err = cli(*args)
    assert json.loads(again) == rows
    assert "resuming: 6 of 6 points reused" in err


def test_bad_sweep_range_is_exit_2(cli, tmp_path) -> None:
    from tests.conftest import PROBLEMS

    code, _, err = cli(
        "sweep", PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml", "--param", "v=a:b", "--out", tmp_path
    )
    assert code == 2 and "cannot read the values" in err


def test_sweep_folder_shared_by_different_problems_keeps_them_apart(cli, tmp_path) -> None:
    import json

    from tests.conftest import PROBLEMS

    path = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"
    base = ("sweep", path, "--param", "v=0.4,0.6", "--out", tmp_path, "--json")
    _, first, _ = cli(*base)
    _, moved, _ = cli(*base, "--set", "problem.parameters.r0=2.0")
    for a, b in zip(json.loads(first), json.loads(moved), strict=True):
        assert b["t_final"] == pytest.approx((2.0 - 0.001) / (1.0 - b["v"]), abs=1e-6)
        assert a["t_final"] == pytest.approx((1.0 - 0.001) / (1.0 - a["v"]), abs=1e-6)


def test_failed_points_are_solved_again_on_a_rerun(tmp_path) -> None:
    store = ResultStore(tmp_path)
    store.put("x=1", {"status": "error"})
    values = run_study(
        {"x=1": 1},
        lambda x: {"status": "optimal", "x": x},
        store,
        show_progress=False,
        accept=lambda v: v["status"] == "optimal",
    ).values
    assert values == {"x=1": {"status": "optimal", "x": 1}}
