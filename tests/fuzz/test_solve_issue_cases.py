"""The solve-path inputs of issue 27, one case each: every one is refused at load with one line
naming the file and the field (exit 2), within the CPU-time bound of :mod:`tests.fuzz.harness`."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.conftest import PROBLEMS
from tests.fuzz.harness import check

ASYMMETRIC = PROBLEMS / "ch7" / "asymmetric_obstacle.yaml"
CHAUFFEUR = PROBLEMS / "ch7" / "homicidal_chauffeur.yaml"
HUGO = PROBLEMS / "ch5" / "hurricane_hugo.yaml"
CASES = [
    (ASYMMETRIC, ['problem.states.xe.initial="\\t"'], "problem.states.xe.initial"),
    (ASYMMETRIC, ['problem.states.xe.initial="not x"'], "problem.states.xe.initial"),
    (ASYMMETRIC, ["problem.states.xe.initial=1e+300"], "problem.states.xe.initial"),
    (ASYMMETRIC, ['problem.dynamics.yp="acos(c*1e18)"'], "problem.dynamics.yp"),
    (CHAUFFEUR, ['problem.dynamics.xe="sqrt(-w2)"'], "problem.dynamics.xe"),
    (CHAUFFEUR, ["problem.parameters.T=700", 'problem.dynamics.yp="exp(T)*exp(T)"'], "problem.dynamics.yp"),
    (
        ASYMMETRIC,
        ['receding_horizon.positions.evader.0="exp(ve)*exp(ve)"', "problem.parameters.ve=710"],
        "receding_horizon.positions.evader",
    ),
    (ASYMMETRIC, ["receding_horizon.step=0.15"], "receding_horizon.step"),
    (PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml", ['capture_radius="2.5"'], "capture_radius"),
    (
        PROBLEMS / "ch6" / "rcs_single_obstacle.yaml",
        ['transforms.0.moving_obstacles.obstacles.obstacle.center.0="sqrt(-Q)"'],
        "transforms.0.moving_obstacles.obstacles.obstacle.center.0",
    ),
    (HUGO, ["method.grid.nodes=[2001, 2001]"], "method.grid.nodes"),
    (HUGO, ["method.cfl=1e-300"], "method.grid.nodes"),
    (HUGO, ["method.extremals.step=1e-300"], "method.extremals.step"),
    (HUGO, ["method.extremals.directions=20000"], "method.extremals.step"),
    (PROBLEMS / "ch4" / "missile_endgame.yaml", ["problem.parameters.alpha=1e300"], "problem.continuous"),
]


@pytest.mark.parametrize(("path", "assignments", "field"), CASES, ids=[c[2] for c in CASES])
def test_refused_at_load_naming_the_field(path: Path, assignments: list[str], field: str) -> None:
    outcome = check(["solve", path, *(x for a in assignments for x in ("--set", a))], str(path), "--set")
    assert outcome.code == 2, outcome
    assert outcome.err.startswith(f"error: {path}: {field}: "), outcome.err
