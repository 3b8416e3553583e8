"""``validate`` checks a file's transform options against its problem as ``solve`` does (issue 28
item 5): a misspelled sensitivity weight, a player's regularizer naming no constraint, each a
one-line exit 2 naming the field; ``show --transformed`` prints a differential game's players'
transformed best-response problems, not the untransformed game."""

from __future__ import annotations

import yaml

from tests.conftest import PROBLEMS

ZERMELO = PROBLEMS / "ch6" / "zermelo_trajectory_desensitized.yaml"
CHAPTER_7 = PROBLEMS / "ch7" / "asymmetric_obstacle.yaml"


def test_a_misspelled_sensitivity_weight_is_refused_by_validate_as_by_solve(cli) -> None:
    wrong = "transforms.0.desensitize.trajectory={S_x1_rh: 50}"
    code, _, err = cli("validate", ZERMELO, "--set", wrong)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "S_x1_rh" in err and "transforms" in err and "S_x1_rho" in err
    samples = "transforms.0.desensitize.monte_carlo.samples=0"
    solve_code, _, solve_err = cli("solve", ZERMELO, "--set", wrong, "--set", samples)
    assert solve_code == 2 and solve_err.strip().split(": ", 1)[1] == err.strip().split(": ", 1)[1]
    assert cli("validate", ZERMELO)[0] == 0


def test_a_players_transform_options_are_checked_at_validate(cli) -> None:
    code, _, err = cli(
        "validate", CHAPTER_7, "--set", "problem.players.pursuer.transforms.0.rcs.constraints=[5]"
    )
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "problem.players.pursuer.transforms.0" in err and "[5]" in err
    assert cli("validate", CHAPTER_7)[0] == 0


def test_show_transformed_prints_each_players_transformed_problem(cli) -> None:
    """At Q = 1 the pursuer's regularizer (rcs) is in the pursuer's own problem (S_g states and
    the weighted cost) and in the evader's game is not applied (the evader does not know it)."""
    code, out, err = cli("show", CHAPTER_7, "--transformed", "--set", "problem.parameters.Q=1")
    assert code == 0, err
    shown = yaml.safe_load(out)
    assert set(shown) == {"game of pursuer", "game of evader"}
    own = shown["game of pursuer"]["pursuer"]
    assert own["kind"] == "optimal_control" and not own.get("transforms")
    assert any(name.startswith("S_") for name in own["problem"]["states"])
    believed = shown["game of evader"]["pursuer"]
    assert not any(name.startswith("S_") for name in believed["problem"]["states"])
    code, plain, _ = cli("show", CHAPTER_7)
    assert code == 0 and yaml.safe_load(plain)["kind"] == "differential_game"
