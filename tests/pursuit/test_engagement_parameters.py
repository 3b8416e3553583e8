"""Runtime parameters of engagements through the engagement → OCP transform: the user's dotted
names, a re-solve of the compiled OCP equal to a fresh solve, agreement with the closed form, and
the backend that really solved it."""

from __future__ import annotations

import json

import pytest

import gamespec
from gamespec.errors import SpecError
from gamespec.studies.sweep import sweep
from tests.conftest import PROBLEMS

ENGAGEMENTS = sorted(
    path
    for chapter in ("ch2", "ch3")
    for path in (PROBLEMS / chapter).glob("*.yaml")
    if gamespec.load(path).kind == "engagement"
)
CB_TWO_ON_ONE = PROBLEMS / "ch2" / "constant_bearing_two_on_one.yaml"
COLLINEAR = PROBLEMS / "ch2" / "pp_collinear_behind.yaml"


@pytest.mark.parametrize("path", ENGAGEMENTS, ids=lambda p: p.stem)
def test_resolve_with_new_speeds_equals_a_fresh_solve(path) -> None:
    """One compiled OCP re-solved for a slower evader and a faster first pursuer is the OCP a fresh
    compile of the overridden file builds, started from the same guess: the same answer."""
    spec = gamespec.load(path)
    changes = {"evader.speed": 0.9 * spec.evader.speed, "pursuers.0.speed": 1.1 * spec.pursuers[0].speed}
    solver = gamespec.compile_spec(spec)
    again = solver.solve(parameters=changes)
    fresh = gamespec.solve(gamespec.load(path, [f"{k}={v!r}" for k, v in changes.items()]))
    assert again.status == fresh.status
    assert again.ok
    assert again.t_final == pytest.approx(fresh.t_final, rel=1e-9)
    assert again.metrics["capturing_set"] == fresh.metrics["capturing_set"]
    assert again.parameters == fresh.parameters
    assert again.parameters["evader.speed"] == changes["evader.speed"]
    assert again.t_final != pytest.approx(solver.solve().t_final, rel=1e-6)


def test_sweep_over_evader_speed_matches_the_closed_form(tmp_path) -> None:
    """`gamespec sweep --param evader.speed=...` of the two-on-one constant-bearing engagement: at each
    speed the OCP's capture time is the analytic backend's (§2.4.1) at that speed."""
    speeds = [0.3, 0.4, 0.5]
    run = sweep(CB_TWO_ON_ONE, [("evader.speed", speeds)], out=tmp_path, show_progress=False)
    rows = list(run.values.values())
    assert [row["evader.speed"] for row in rows] == speeds
    for row, v in zip(rows, speeds, strict=True):
        analytic = gamespec.solve(gamespec.load(CB_TWO_ON_ONE, [f"evader.speed={v}"]), "analytic")
        assert row["status"] == "optimal"
        assert row["t_final"] == pytest.approx(analytic.t_final, rel=1e-6)
    assert len({round(row["t_final"], 6) for row in rows}) == len(speeds)


def test_analytic_backend_takes_the_same_parameters() -> None:
    solver = gamespec.compile_spec(CB_TWO_ON_ONE, "analytic")
    slow = solver.solve(parameters={"evader.speed": 0.3})
    fresh = gamespec.solve(gamespec.load(CB_TWO_ON_ONE, ["evader.speed=0.3"]), "analytic")
    assert slow.t_final == pytest.approx(fresh.t_final, rel=1e-12)
    assert slow.t_final != pytest.approx(solver.solve().t_final, rel=1e-6)


def test_set_by_index_and_by_brackets(cli) -> None:
    dotted = cli("solve", CB_TWO_ON_ONE, "--set", "pursuers.1.speed=1.6", "--json")
    brackets = cli("solve", CB_TWO_ON_ONE, "--set", "pursuers[1].speed=1.6", "--json")
    assert dotted[0] == brackets[0] == 0
    t_dotted, t_brackets = (json.loads(out)["t_final"] for _, out, _ in (dotted, brackets))
    again = gamespec.compile_spec(CB_TWO_ON_ONE).solve(parameters={"pursuers.1.speed": 1.6})
    assert t_dotted == t_brackets == pytest.approx(again.t_final, rel=1e-9)
    code, _, err = cli("solve", CB_TWO_ON_ONE, "--set", "pursuers.2.speed=1.6")
    assert code == 2
    assert "pursuers has entries 0 to 1" in err


def test_runtime_parameters_are_validated_as_at_load() -> None:
    solver = gamespec.compile_spec(CB_TWO_ON_ONE)
    with pytest.raises(SpecError, match="assumption A1"):
        solver.solve(parameters={"evader.speed": 1.2})
    with pytest.raises(SpecError, match="unknown parameter 'v'"):
        solver.solve(parameters={"v": 0.3})
    with pytest.raises(SpecError, match=r"did you mean 'evader\.speed'"):
        solver.solve(parameters={"evader.sped": 0.3})
    with pytest.raises(SpecError, match=r"pursuers\.0\.strategy change"):
        solver.solve(parameters={"pursuers.0.strategy": "pp"})


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_multistart_runs_on_the_callers_backend(backend) -> None:
    """On a uniform grid the collinear engagement's first NLP solution fails verification; the
    solving layer re-solves the same compiled model, so the Result is the caller's backend's."""
    result = gamespec.solve(gamespec.load(COLLINEAR, ["method.grading=1"]), backend)
    assert result.status == gamespec.Status.OPTIMAL
    assert "re-solve from starting point" in result.message
    assert result.backend == backend
    assert ("executable" in result.solver_stats) == (backend == "pyomo")
    assert ("return_status" in result.solver_stats) == (backend == "casadi")
