"""The Table 2.1 study (kind ``pursuit_suboptimal_study``): its grid lies in N, it runs through
``gamespec solve``, points are saved as they finish, a rerun resumes, the status says what failed."""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import pytest

import gamespec
from gamespec.pursuit import regions
from gamespec.result import Result
from gamespec.studies.store import ResultStore
from gamespec.suboptimal_study import points as study
from gamespec.suboptimal_study import study as suboptimal_study
from gamespec.suboptimal_study.points import StudyPoint
from gamespec.summaries import outcome
from tests.conftest import PROBLEMS

STUDY = PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml"
TINY = ["--set", "speeds=[0.5]", "--set", "grid.angles=2", "--set", "grid.fractions=2"]
"""One speed, two angles, two fractions: four points."""


def test_shipped_grid_spans_n_only() -> None:
    spec = gamespec.load(STUDY)
    points = study.study_points(spec)
    assert len(points) == len(spec.speeds) * spec.grid.angles * spec.grid.fractions
    for p in points.values():
        p2 = np.array([p.r1 + p.r2 * np.cos(p.psi), p.r2 * np.sin(p.psi)])
        assert regions.classify("pp", [0, 0], p2, [p.r1, 0], p.u, p.u, p.v) == "N"


@pytest.mark.parametrize("v", [0.3, 0.7])
def test_ray_bounds_are_the_region_boundaries(v: float) -> None:
    """Just inside F is D1, just outside E is D2, in between is N (§2.3.2)."""
    psi = np.linspace(-3.0, 3.0, 13)
    inner, outer = study.ray_bounds(1.0, 1.0, v, psi)
    ray = np.column_stack([np.cos(psi), np.sin(psi)])
    e = np.array([1.0, 0.0])

    def region(r: np.ndarray) -> np.ndarray:
        return regions.classify("pp", [0, 0], e + r[:, None] * ray, e, 1.0, 1.0, v)

    assert np.all(region(0.99 * inner) == "D1")
    assert np.all(region(0.5 * (inner + outer)) == "N")
    assert np.all(region(1.01 * outer) == "D2")


def test_shipped_file_validates(cli) -> None:
    code, _, err = cli("validate", STUDY)
    assert code == 0, err


def test_solve_saves_points_resumes_and_plots(tmp_path, monkeypatch, cli) -> None:
    store, run = tmp_path / "points", tmp_path / "run"
    args = ("solve", STUDY, *TINY, "--set", f"store={store}", "--out", run, "--json")
    code, out, err = cli(*args)
    assert code == 0, err
    first = json.loads(out)
    assert first["status"] == "optimal"
    assert first["metrics"]["points"] == first["metrics"]["solved"] == first["metrics"]["computed"] == 4
    assert len(ResultStore(store).done()) == 4
    row = first["metrics"]["table"][0]
    assert row["points"] == row["solved"] == 4
    variation = np.array(first["arrays"]["variation_percent"])
    assert row["average_variation_percent"] == pytest.approx(variation.mean())
    assert row["maximum_variation_percent"] == pytest.approx(variation.max())

    def must_not_run(point: StudyPoint) -> dict[str, Any]:
        raise AssertionError("a saved point was solved again")

    monkeypatch.setattr(suboptimal_study, "evaluate", must_not_run)
    code, out, err = cli(*args)
    assert code == 0, err
    again = json.loads(out)
    assert again["metrics"]["computed"] == 0
    assert again["metrics"]["table"] == first["metrics"]["table"]
    rows = dict(outcome(Result.load(run)))
    assert (rows["points"], rows["solved"], rows["computed in this run"]) == (4, 4, 0)
    assert rows["store"] == str(store)

    code, out, err = cli("plot", run)
    assert code == 0, err
    assert (run / "variation.png").exists()

    code, out, err = cli("pursuit", "study", STUDY, *TINY, "--out", tmp_path, "--json")
    assert code == 0, err
    assert json.loads(out) == first["metrics"]["table"]


def _solved_when_psi_positive(point: StudyPoint) -> dict[str, Any]:
    """A stand-in for :func:`suboptimal_study.evaluate`: the points with ψ(0) > 0 get a (made-up) optimum."""
    row = {"v": point.v, "r2": point.r2, "psi": point.psi, "t_suboptimal": 1.0, "max_defect": 0.0}
    if point.psi > 0:
        row |= {"t_optimal": 1.0, "variation_percent": 0.0}
        row |= {"simultaneous_capture_gap": 0.0, "resimulated_capture_time_error": 0.0}
    return row


def test_points_left_out_make_the_result_feasible(tmp_path, monkeypatch, cli) -> None:
    monkeypatch.setattr(suboptimal_study, "evaluate", _solved_when_psi_positive)
    code, out, err = cli("solve", STUDY, *TINY, "--set", f"store={tmp_path}", "--json")
    assert code == 0, err
    result = json.loads(out)
    assert result["status"] == "feasible"
    assert "2 of 4 points left out" in result["message"]
    assert result["metrics"]["table"][0]["solved"] == 2


def test_no_point_solved_is_an_error(tmp_path, monkeypatch, cli) -> None:
    monkeypatch.setattr(suboptimal_study, "evaluate", _solved_when_psi_positive)
    code, _, err = cli("solve", STUDY, *TINY, "--set", "grid.angles=1", "--set", f"store={tmp_path}")
    assert code == 1
    assert "none of the 2 points solved" in err


def test_an_edited_setup_does_not_reuse_points() -> None:
    """Point keys carry a hash of r1, u, capture radius, methods and backend."""
    spec = gamespec.load(STUDY, ["speeds=[0.5]", "grid.angles=2", "grid.fractions=1"])
    keys = set(study.study_points(spec))
    for change in ("capture_radius=0.002", "method.intervals=50", "ocp_backend=pyomo"):
        edited = gamespec.load(STUDY, ["speeds=[0.5]", "grid.angles=2", "grid.fractions=1", change])
        assert keys.isdisjoint(study.study_points(edited)), change


def test_study_rows_compare_to_a_full_solve() -> None:
    """A study point's optimum (compiled once, re-solved with new parameters) equals a fresh solve
    of the same engagement, and its suboptimal time equals the analytic backend's."""
    point = next(iter(study.study_points(gamespec.load(STUDY)).values()))
    row = suboptimal_study.evaluate(point)
    engagement = study.point_engagement(point)
    assert row["t_optimal"] == pytest.approx(gamespec.solve(engagement).t_final, rel=1e-6)
    assert row["t_suboptimal"] == pytest.approx(gamespec.solve(engagement, "analytic").t_final, rel=1e-9)


@pytest.mark.parametrize(
    ("override", "field"),
    [("speeds=[1.5]", "speeds"), ("refinements=[{intervals: 0}]", "refinements")],
)
def test_bad_study_file_names_the_field(cli, override: str, field: str) -> None:
    code, _, err = cli("validate", STUDY, "--set", override)
    assert code == 2
    assert len(err.strip().splitlines()) == 1
    assert field in err
