"""Declared analyses (:mod:`gamespec.analyses`): on by default, off or chosen by name, cached, and a
status that claims no more than was checked (``docs/statuses.md``).

What the analyses write is checked against the engines run directly on the same Result: the
Monte Carlo and LQR tracking of :mod:`gamespec.desensitize.montecarlo` (§6.3.1, eqs. 6.27-6.29)
and an ODE re-simulation of the engagement under the solution's heading (eq. 2.1).
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import gamespec
from gamespec import registry
from gamespec.analyses import CACHE, SKIPPED, Analysis, Outputs, for_study, parse_selection, selected
from gamespec.desensitize import montecarlo, penalized
from gamespec.desensitize.spec import MonteCarloOptions
from gamespec.errors import SpecError
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.pursuit.ocp_generation import to_ocp
from gamespec.pursuit.ocp_report import heading_law
from gamespec.pursuit.simulation import simulate_to_capture
from gamespec.result import Status
from gamespec.solving import compile_spec, solve
from tests.conftest import PROBLEMS

BOAT = PROBLEMS / "ch6" / "zermelo_trajectory_desensitized.yaml"
SMALL = ["transforms.0.desensitize.monte_carlo.samples=200"]
"""The file's Monte Carlo (with LQR tracking) at 200 samples, to keep the tests cheap."""
ENGAGEMENT = PROBLEMS / "ch2" / "constant_bearing_two_on_one.yaml"
ZERMELO = PROBLEMS / "ch6" / "zermelo_min_time.yaml"


@pytest.fixture(scope="module")
def boat():
    return gamespec.load(BOAT, SMALL)


@pytest.fixture(scope="module")
def boat_all(boat):
    return solve(boat)


@pytest.fixture(autouse=True)
def _fresh_cache():
    CACHE.clear()


def test_default_writes_what_the_monte_carlo_engine_computes(boat, boat_all) -> None:
    source = compile_spec(boat, analyses="none").steps[0].source
    ocp, uncertain = SymbolicOcp(source), source.problem.uncertain
    options = boat.transforms[0]["desensitize"]["monte_carlo"]
    carlo = MonteCarloOptions.model_validate(options)
    open_loop, bundle = montecarlo.monte_carlo(ocp, boat_all, uncertain, carlo)
    closed, closed_bundle = montecarlo.tracking(ocp, boat_all, uncertain, carlo)
    assert boat_all.status is Status.OPTIMAL
    assert boat_all.metrics["monte_carlo"] == open_loop | {"tracking": closed}
    for name, values in (bundle | closed_bundle).items():
        np.testing.assert_array_equal(boat_all.arrays[name], values)


def test_none_skips_them_and_keeps_the_status_of_the_solve(boat, boat_all) -> None:
    off = solve(boat, analyses="none")
    assert "monte_carlo" not in off.metrics
    assert not any(name.startswith(("monte_carlo_", "tracking_")) for name in off.arrays)
    assert off.status is Status.OPTIMAL  # the Monte Carlo decides no check
    assert "checks_skipped" not in off.metrics
    assert off.objective == pytest.approx(boat_all.objective, rel=1e-12)
    assert off.metrics["sensitivity_cost"] == pytest.approx(boat_all.metrics["sensitivity_cost"], rel=1e-9)


def test_a_named_selection_runs_those_and_what_they_need(boat) -> None:
    only = solve(boat, analyses=["monte_carlo"])
    assert "tracking" not in only.metrics["monte_carlo"]
    assert "monte_carlo_x1" in only.arrays and "tracking_x1" not in only.arrays
    tracked = solve(boat, analyses=["lqr_tracking"])
    assert "tracking" in tracked.metrics["monte_carlo"]
    assert {"monte_carlo_x1", "tracking_x1"} <= set(tracked.arrays)


def test_a_repeated_solve_reads_the_cache(boat, monkeypatch) -> None:
    calls = {"monte_carlo": 0, "tracking": 0}

    def counted(name):
        engine = getattr(montecarlo, name)

        def run(*args, **kwargs):
            calls[name] += 1
            return engine(*args, **kwargs)

        return run

    for name in calls:
        monkeypatch.setattr(penalized, name, counted(name))
    solver = compile_spec(boat)
    first, again = solver.solve(), solver.solve()
    assert calls == {"monte_carlo": 1, "tracking": 1}
    assert again.metrics["monte_carlo"] == first.metrics["monte_carlo"]
    moved = solver.solve(parameters={"alpha": 200.0})
    assert calls == {"monte_carlo": 2, "tracking": 2}
    assert moved.metrics["monte_carlo"] != first.metrics["monte_carlo"]


def test_an_unknown_name_is_an_error_listing_the_known_ones(boat) -> None:
    with pytest.raises(
        SpecError, match=r"unknown analysis 'montecarlo' \(known: .*monte_carlo.*resimulation"
    ):
        compile_spec(boat, analyses=["monte_carlo", "montecarlo"])
    with pytest.raises(SpecError, match="analyses: unknown analysis 'montecarlo'"):
        gamespec.load(BOAT, ["analyses=[montecarlo]"])
    with pytest.raises(SpecError, match="analyses: give all, none"):
        gamespec.load(BOAT, ["analyses=some"])


def test_the_file_key_chooses_and_the_argument_wins(boat) -> None:
    keyed = gamespec.load(BOAT, [*SMALL, "analyses=none"])
    assert "monte_carlo" not in solve(keyed).metrics
    assert "monte_carlo" in solve(keyed, analyses=["monte_carlo"]).metrics


def _resimulated_capture_time(spec, result) -> float:
    _, inverse = to_ocp(spec)
    traj = simulate_to_capture(inverse.players, heading_law(inverse.reduction, result))
    assert traj.captured
    return traj.capture_time


def test_the_engagement_is_verified_by_its_resimulation_and_not_claimed_optimal_without_it() -> None:
    spec = gamespec.load(ENGAGEMENT)
    on = solve(spec)
    assert on.status is Status.OPTIMAL
    assert on.checks["resimulated_capture_time"] == pytest.approx(
        _resimulated_capture_time(spec, on), rel=1e-9
    )
    assert on.checks["resimulated_capture_time"] == pytest.approx(on.t_final, rel=1e-3)
    off = solve(spec, analyses="none")
    assert off.status is Status.FEASIBLE
    assert off.metrics["checks_skipped"]["resimulated_capture_time"] == SKIPPED
    assert "resimulated_capture_time" not in off.checks and "path_evader" not in off.arrays
    assert "resimulated_capture_time skipped (analyses off)" in off.message
    assert off.t_final == pytest.approx(on.t_final, rel=1e-12)
    assert off.metrics["capturing_set"] == on.metrics["capturing_set"]
    named = solve(spec, analyses=["resimulation"])
    assert named.status is Status.OPTIMAL and named.checks == on.checks


@pytest.fixture
def fresh_registry():
    registry.load.cache_clear()
    yield
    registry.load.cache_clear()


def test_a_kind_declares_analyses_in_its_kind(monkeypatch, fresh_registry) -> None:
    seen = []

    def final_x(result, spec, inverse) -> Outputs:
        seen.append(inverse)
        return Outputs(metrics={"final_x": float(result.states["x1"][-1])}, checks={"final_x_error": 0.0})

    declared = [Analysis("final_x", final_x, "the final x", checks=("final_x_error",))]
    kind = dataclasses.replace(registry.kind("optimal_control"), analyses=declared)
    monkeypatch.setitem(registry._IN_PROCESS["gamespec.kinds"], "optimal_control", kind)
    registry.load.cache_clear()
    on = solve(ZERMELO, analyses=["final_x"])
    assert on.metrics["final_x"] == pytest.approx(on.states["x1"][-1]) and seen == [None]
    off = solve(ZERMELO, analyses="none")
    assert "final_x" not in off.metrics
    assert off.metrics["checks_skipped"]["final_x_error"] == SKIPPED
    assert on.status is Status.OPTIMAL and off.status is Status.FEASIBLE


def test_selections_read_and_close_over_needs() -> None:
    a = Analysis("a", lambda r, s, i: Outputs(), "")
    b = Analysis("b", lambda r, s, i: Outputs(), "", needs=("a",))
    assert [x.name for x in selected([a, b], ["b"])] == ["a", "b"]
    assert selected([a, b], "none") == [] and selected([a, b], "all") == [a, b]
    assert parse_selection("none") == "none" and parse_selection(" a, b ") == ["a", "b"]
    assert for_study(None, ["a"]) == ["a"] == for_study("none", ["a"])
    assert for_study(["b", "a"], ["a"]) == ["a", "b"] and for_study("all", ["a"]) == "all"


def test_the_command_line_flag(cli, tmp_path) -> None:
    code, out, _ = cli("solve", ENGAGEMENT, "--json", "--analyses", "none")
    data = json.loads(out)
    assert code == 0 and data["status"] == "feasible"
    assert data["metrics"]["checks_skipped"] == {"resimulated_capture_time": SKIPPED}
    code, _, err = cli("solve", ENGAGEMENT, "--analyses", "resim")
    assert code == 2 and "unknown analysis 'resim'" in err and "resimulation" in err
    code, out, _ = cli(
        "sweep",
        ENGAGEMENT,
        "--param",
        "evader.speed=0.4,0.5",
        "--out",
        tmp_path,
        "--json",
        "--analyses",
        "none",
    )
    rows = json.loads(out)
    assert code == 0 and [r["status"] for r in rows] == ["feasible", "feasible"]
    assert all(r["metrics"]["checks_skipped"] == {"resimulated_capture_time": SKIPPED} for r in rows)
