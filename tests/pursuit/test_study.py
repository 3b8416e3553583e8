"""The Table 2.1 study: its grid lies in N, points are saved as they finish, a rerun resumes."""

from __future__ import annotations

import json

import numpy as np
import pytest

import gamespec
from gamespec.pursuit import regions, study
from tests.conftest import PROBLEMS

STUDY = PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml"


def test_shipped_grid_spans_n_only() -> None:
    spec = study.load_study(STUDY)
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


def test_study_saves_points_and_resumes(tmp_path, monkeypatch, cli) -> None:
    file = tmp_path / "study.yaml"
    file.write_text(
        "study: pure_pursuit_suboptimal_vs_optimal\nspeeds: [0.5]\ngrid: {angles: 2, fractions: 1}\n"
    )
    code, out, err = cli("pursuit", "study", file, "--out", tmp_path / "run", "--json")
    assert code == 0, err
    table = json.loads(out)
    assert table[0]["points"] == table[0]["solved"] == 2
    assert table[0]["average_variation_percent"] >= 0.0
    assert len(list((tmp_path / "run" / "points").glob("*.json"))) == 2
    assert (tmp_path / "run" / "table_2_1.png").exists()

    def must_not_run(point):
        raise AssertionError("a saved point was solved again")

    monkeypatch.setattr(study, "evaluate", must_not_run)
    assert study.run(study.load_study(file), tmp_path / "run", progress=False) == table


def test_study_rows_compare_to_a_full_solve() -> None:
    """A study point's optimum (compiled once, re-solved with new parameters) equals a fresh solve
    of the same engagement, and its suboptimal time equals the analytic backend's."""
    spec = study.load_study(STUDY)
    point = next(iter(study.study_points(spec).values()))
    row = study.evaluate(point)
    engagement = study.point_engagement(point)
    assert row["t_optimal"] == pytest.approx(gamespec.solve(engagement).t_final, rel=1e-6)
    assert row["t_suboptimal"] == pytest.approx(gamespec.solve(engagement, "analytic").t_final, rel=1e-9)


def test_bad_study_file_names_the_field(tmp_path) -> None:
    file = tmp_path / "study.yaml"
    file.write_text("study: pure_pursuit_suboptimal_vs_optimal\nspeeds: [1.5]\n")
    with pytest.raises(gamespec.SpecError, match="speeds"):
        study.load_study(file)
