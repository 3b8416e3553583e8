"""A solve's summary prints the headline numbers of the transforms it went through (issue 28 item
1): a desensitized file its sensitivities and Monte Carlo spread, an RCS file its collision
probability with the interval — read from real solves, every row naming a number the Result holds."""

from __future__ import annotations

import gamespec
from gamespec.summaries import outcome
from tests.conftest import PROBLEMS


def _rows(path: str, *sets: str) -> tuple[gamespec.Result, dict[str, object]]:
    result = gamespec.solve(gamespec.load(PROBLEMS / path, list(sets)))
    return result, dict(outcome(result))


def test_desensitized_summary_has_sensitivities_and_the_monte_carlo_spread() -> None:
    result, rows = _rows(
        "ch6/zermelo_trajectory_desensitized.yaml", "transforms.0.desensitize.monte_carlo.samples=200"
    )
    assert result.provenance.transforms[0] == "desensitize"
    m = result.metrics
    assert rows["nominal objective"] == m["nominal_objective"]
    assert rows["sensitivity cost"] == m["sensitivity_cost"]
    assert rows["S(t_f) S_x1_rho"] == m["final_sensitivity"]["S_x1_rho"]
    mc = m["monte_carlo"]
    mean, std = mc["final_state_mean"]["x1"], mc["final_state_std"]["x1"]
    assert rows["Monte Carlo x1(t_f)"] == f"{mean:.6g} ± {std:.3g}"
    assert "LQR tracking x1(t_f)" in rows and "LQR tracking energy ∫Δu²" in rows
    assert "Monte Carlo S_x1_rho(t_f)" not in rows, "only the original states are sampled"


def test_rcs_summary_has_the_collision_probability_with_its_interval() -> None:
    result, rows = _rows("ch6/rcs_single_obstacle.yaml", "transforms.1.rcs.monte_carlo.samples=200")
    mc = result.metrics["monte_carlo"]
    low, high = mc["collision_probability_ci"]
    assert rows["collision probability P_c"] == f"{mc['collision_probability']:.4g} [{low:.3g}, {high:.3g}]"
    assert rows["Monte Carlo samples"] == 200
