"""``gamespec results RESULT_DIR --csv F``: one Result's trajectories, each on its own grid."""

from __future__ import annotations

import csv

import numpy as np

from gamespec.cli import run
from gamespec.result import Result, Status
from tests.conftest import PROBLEMS


def _read(path) -> list[dict[str, str]]:
    with path.open() as handle:
        return list(csv.DictReader(handle))


def test_one_results_trajectories_round_trip_through_csv(tmp_path) -> None:
    out = tmp_path / "bd"
    assert run(["solve", str(PROBLEMS / "ocp" / "bryson_denham.yaml"), "--out", str(out)]) == 0
    assert run(["results", str(out), "--csv", str(tmp_path / "bd.csv")]) == 0
    saved = Result.load(out)
    rows = _read(tmp_path / "bd.csv")
    grids = {
        "x": saved.time,
        "lambda_x": saved.arrays["costate_time"],
        "u": saved.control_time if saved.control_time is not None else saved.time,
    }
    values = {"x": saved.states["x"], "lambda_x": saved.costates["lambda_x"], "u": saved.controls["u"]}
    for name, grid in grids.items():
        written = [(float(r["t"]), float(r[name])) for r in rows if r[name] != ""]
        np.testing.assert_array_equal([t for t, _ in written], grid)
        np.testing.assert_array_equal([v for _, v in written], values[name])
    assert [float(r["t"]) for r in rows] == sorted(float(r["t"]) for r in rows)


def test_a_repeated_time_stays_two_rows(tmp_path) -> None:
    """A phase boundary (a time the grid holds twice) keeps both values."""
    result = Result(
        problem="r", status=Status.OPTIMAL, time=np.array([0.0, 1.0, 1.0, 2.0]), states={"x": [0, 1, 5, 6]}
    )
    result.save(tmp_path / "r")
    assert run(["results", str(tmp_path / "r"), "--csv", str(tmp_path / "r.csv")]) == 0
    rows = _read(tmp_path / "r.csv")
    assert [(r["t"], r["x"]) for r in rows] == [
        ("0.0", "0.0"),
        ("1.0", "1.0"),
        ("1.0", "5.0"),
        ("2.0", "6.0"),
    ]


def test_a_result_without_trajectories_is_refused_for_export(tmp_path, capsys) -> None:
    Result(problem="r", status=Status.OPTIMAL, objective=1.0).save(tmp_path / "r")
    assert run(["results", str(tmp_path / "r"), "--csv", str(tmp_path / "r.csv")]) == 2
    assert "no trajectories" in capsys.readouterr().err
