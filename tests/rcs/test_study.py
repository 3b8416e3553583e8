"""The §6.4.4 study: a reduced version through the CLI (saved points, resume, table, plot), the
full one marked slow; bad requests exit 2."""

import json

import pytest
import yaml

from gamespec.rcs.study_points import layout
from gamespec.rcs.study_spec import RcsStudySpec
from gamespec.result import Result
from gamespec.summaries import outcome
from tests.conftest import PROBLEMS

STUDY = PROBLEMS / "ch6" / "rcs_multi_obstacle_study.yaml"
ROW_FIELDS = {
    "obstacles",
    "alpha",
    "t_final",
    "t_final_increase",
    "collision_probability",
    "collision_reduction",
}


def test_every_obstacle_blocks_the_straight_path():
    spec = RcsStudySpec(name="s")
    for n in spec.obstacles:
        for x, y0, direction in layout(spec, n):
            crossing = y0 + direction * spec.rho * (x / spec.v_max)  # where it is when the agent gets there
            assert abs(crossing) < 1e-12


def test_sigma_readings():
    assert RcsStudySpec(name="s", sigma=0.1).std == pytest.approx(0.1)
    assert RcsStudySpec(name="s", sigma=0.1, sigma_is="variance").std == pytest.approx(0.1**0.5)


def reduced(tmp_path):
    data = yaml.safe_load(STUDY.read_text())
    data |= {"obstacles": [2], "alphas": [0.0, 1.0], "guesses": [4.0], "samples": 300, "steps": 400}
    data["store"] = str(tmp_path / "points")
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_reduced_study_through_the_cli(cli, tmp_path):
    path = reduced(tmp_path)
    code, out, _ = cli("solve", str(path), "--set", "sigma=0.1", "--json")
    assert code == 0
    result = json.loads(out)
    table = result["metrics"]["table"]
    assert len(table) == 2 and all(set(row) >= ROW_FIELDS for row in table)
    for row in table:
        assert row["sigma"] == pytest.approx(0.1) and row["status"] in ("optimal", "feasible")
        low, high = row["collision_probability_ci"]
        assert low <= row["collision_probability"] <= high and row["objective"] >= row["t_final"]
    base, weighted = table
    assert base["t_final_increase"] == 0 and weighted["t_final_increase"] > 0
    assert weighted["collision_probability"] < base["collision_probability"]
    assert weighted["collision_reduction"] > 0
    assert result["metrics"]["sigma"] == pytest.approx(0.1)
    code, out, _ = cli("solve", str(path), "--set", "sigma=0.1", "--json", "--out", str(tmp_path / "res"))
    assert code == 0 and json.loads(out)["metrics"]["computed"] == 0  # resumed from the store
    rows = dict(outcome(Result.load(tmp_path / "res")))
    assert rows["points"] == rows["solved"] == 2 and rows["computed in this run"] == 0
    assert rows["store"] == str(tmp_path / "points")
    code, out, _ = cli("solve", str(path), "--set", "sigma=0.1")
    assert code == 0 and "computed in this run" in out
    for entry in table:  # the summary: one line per point with its parameters and headline
        line = next(x for x in out.splitlines() if f"N = 2, α = {entry['alpha']:g}, σ = 0.1" in x)
        assert f"P_c = {entry['collision_probability']:.4g} [" in line and entry["status"] in line
    code, out, _ = cli("results", str(tmp_path / "points"))
    assert code == 0
    header = next(x for x in out.splitlines() if "obstacles" in x)
    named = [c for c in header.replace("┃", " ").replace("|", " ").split() if c]
    assert named[:5] == ["obstacles", "alpha", "sigma", "collision_probability", "collision_probability_ci"]
    assert {"status", "objective", "t_final"} <= set(named)
    code, _, _ = cli("plot", str(tmp_path / "res"), "--out", str(tmp_path / "fig"))
    assert code == 0
    assert {p.name for p in (tmp_path / "fig").iterdir()} >= {
        "rcs_multi_obstacle_study_tradeoff.png",
        "rcs_multi_obstacle_study_paths.png",
    }


@pytest.mark.slow
def test_full_study(cli, tmp_path):
    data = yaml.safe_load(STUDY.read_text()) | {"store": str(tmp_path / "points")}
    path = tmp_path / "study.yaml"
    path.write_text(yaml.safe_dump(data))
    code, out, _ = cli("solve", str(path), "--set", "sigma=0.1", "--json")
    assert code == 0
    table = json.loads(out)["metrics"]["table"]
    assert len(table) == 16
    for n in (2, 3, 5, 10):
        rows = [r for r in table if r["obstacles"] == n]
        assert rows[-1]["collision_probability"] < rows[0]["collision_probability"]
        assert rows[-1]["t_final"] > rows[0]["t_final"]


def test_bad_requests_exit_2(cli, tmp_path):
    data = yaml.safe_load((PROBLEMS / "ch6" / "rcs_single_obstacle.yaml").read_text())
    cases = {
        "no_uncertain": lambda d: d["problem"].pop("uncertain"),
        "bad_relevance": lambda d: d["transforms"][1]["rcs"].update(relevance="-w"),
        "bad_constraint": lambda d: d["transforms"][1]["rcs"].update(constraints=[3]),
        "odd_gamma": lambda d: d["transforms"][0]["moving_obstacles"]["obstacles"]["obstacle"].update(
            track={"half_width": 1, "gamma": 3}
        ),
    }
    for name, edit in cases.items():
        case = yaml.safe_load(yaml.safe_dump(data))
        edit(case)
        path = tmp_path / f"{name}.yaml"
        path.write_text(yaml.safe_dump(case))
        code, _, err = cli("solve", str(path))
        assert code == 2, name
        assert len(err.strip().splitlines()) == 1, err
