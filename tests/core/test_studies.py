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
    values = run_study(POINTS, square, ResultStore(tmp_path), executor=runner, show_progress=False)
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

    values = run_study(POINTS, counted, store, show_progress=False)
    assert sorted(calls) == [4, 5]
    assert values == {k: x * x for k, x in POINTS.items()}
