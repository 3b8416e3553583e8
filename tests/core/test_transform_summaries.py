"""A solve's summary prints the headline numbers of the transforms it went through (issue 28 item
1): a desensitized file its sensitivities and Monte Carlo spread, an RCS file its collision
probability with the interval — read from real solves, every row naming a number the Result holds."""

from __future__ import annotations

import numpy as np

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


def test_rcs_summary_has_the_nominal_verdict_and_its_clearance() -> None:
    """The nominal's row (the deterministic nominal, :func:`gamespec.rcs.report.rcs_summary`): its
    verdict is the saved re-simulation's, and the clearance is the smallest distance between the
    agent and the nominal obstacle centre (eq. 6.38 at ρ̂) less r_o, recomputed from the states."""
    from tests.plots import fixtures

    result = fixtures.saved(PROBLEMS / "ch6/rcs_constraint_form.yaml")
    rows = dict(outcome(result))
    mc, p = result.metrics["monte_carlo"], result.parameters
    verdict = "collides" if mc["nominal_violation"] > 1e-6 else "no collision"
    assert rows["nominal (parameters at their values)"].startswith(verdict + ", largest violation")
    x, y, t = result.states["x"], result.states["y"], result.time
    gap = np.hypot(x - p["c"], y + p["d"] - p["rho"] * t) - p["r_o"]
    assert rows["nominal clearance to obstacle"] == f"{gap.min():.4g} at t = {t[np.argmin(gap)]:.4g}"
    assert gap.min() > 0 and not mc["nominal_violated"], "the solved path clears the nominal obstacle"
