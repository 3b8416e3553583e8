"""The one status policy (issue 23, item 1): ``optimal`` only when the solver says so and every
check with a tolerance passes, applied by the chain to every kind; and the property
``optimal => every checks_passed verdict True`` over the shipped problem files on every backend
that takes them (the conftest fixture asserts it on every Result the chain returns in the suite)."""

from __future__ import annotations

import math

import pytest

import gamespec
from gamespec.errors import GamespecError
from gamespec.result import Result, Status
from gamespec.solving import status_policy
from gamespec.summaries import check_rows
from tests.conftest import PROBLEMS, assert_optimal_means_checked


def _result(status: Status, checks: dict, passed: dict, tolerances: dict | None = None) -> Result:
    metrics = {"checks_passed": passed} | ({"check_tolerances": tolerances} if tolerances else {})
    return Result(status=status, message="Solve_Succeeded", checks=checks, metrics=metrics)


def test_a_failed_verdict_turns_optimal_into_feasible_naming_value_and_tolerance() -> None:
    raw = _result(
        Status.OPTIMAL,
        {"max_defect_relative": 4.8e-5, "max_constraint_violation": 0.0},
        {"max_defect_relative": False, "max_constraint_violation": True},
        {"max_defect_relative": 1e-6, "max_constraint_violation": 1e-6},
    )
    judged = status_policy(raw)
    assert judged.status is Status.FEASIBLE
    assert "max_defect_relative = 4.8e-05 > tolerance 1e-06" in judged.message
    assert "max_constraint_violation" not in judged.message
    assert judged.message.startswith("Solve_Succeeded")


@pytest.mark.parametrize("value", [math.nan, None, math.inf])
def test_a_check_that_could_not_be_computed_fails(value) -> None:
    """A NaN (an overflowing re-integration) fails even under a verdict that says True."""
    raw = _result(Status.OPTIMAL, {"max_defect": value}, {"max_defect": True})
    judged = status_policy(raw)
    assert judged.status is Status.FEASIBLE
    assert "max_defect = not computable" in judged.message


def test_a_tolerance_without_a_verdict_is_compared_with_the_value() -> None:
    over = Result(
        status=Status.OPTIMAL, checks={"saddle_gap": 0.1}, metrics={"check_tolerances": {"saddle_gap": 1e-6}}
    )
    under = over.model_copy(update={"checks": {"saddle_gap": 1e-9}})
    assert status_policy(over).status is Status.FEASIBLE
    assert status_policy(under).status is Status.OPTIMAL


def test_other_statuses_and_passing_checks_are_left_alone() -> None:
    failed = _result(Status.ITERATION_LIMIT, {"max_defect": 1.0}, {"max_defect": False})
    passing = _result(Status.OPTIMAL, {"max_defect": 1e-9}, {"max_defect": True})
    assert status_policy(failed) == failed
    assert status_policy(passing) == passing


def test_the_chain_applies_the_policy_to_a_collocation_result() -> None:
    """Ten intervals of the hang glider: IPOPT converges, the relative defect (order 1e-1) fails."""
    result = gamespec.solve(gamespec.load(PROBLEMS / "ocp" / "hang_glider.yaml", ["method.intervals=10"]))
    assert result.status is Status.FEASIBLE
    assert result.metrics["checks_passed"]["max_defect_relative"] is False
    assert result.metrics["check_tolerances"]["max_defect_relative"] == 1e-6
    assert "max_defect_relative" in result.message and "tolerance 1e-06" in result.message


SHIPPED = sorted(PROBLEMS.rglob("*.yaml"))
QUICK = {
    "brachistochrone",
    "bryson_denham",
    "test_example_mean_steering",
    "zermelo_min_time",
    "lq_pursuit_evasion",
}
"""Files whose solve takes about a second or less on every backend that takes them (the default
suite); the others run with ``-m slow``."""


def _backends(path) -> list[str]:
    """Every installed backend that takes the file's kind (after its lowering transforms)."""
    from gamespec import registry
    from gamespec.solving import backend_name, get_backend

    spec = gamespec.load(path)
    names = [backend_name(spec)]
    if spec.kind in {"optimal_control", "multiphase_optimal_control", "engagement"}:
        names += [n for n in registry.names("gamespec.backends") if n in {"casadi", "pyomo"}]
    usable = []
    for name in dict.fromkeys(names):
        try:
            get_backend(name)
        except GamespecError:
            continue
        usable.append(name)
    return usable


@pytest.mark.parametrize(
    "path",
    [
        pytest.param(p, id=p.stem, marks=() if p.stem in QUICK else pytest.mark.slow)
        for p in SHIPPED
        if "study" not in p.stem
    ],
)
def test_optimal_means_every_check_passed_on_the_shipped_files(path) -> None:
    for backend in _backends(path):
        try:
            result = gamespec.solve(gamespec.load(path), backend)
        except GamespecError:  # the backend lacks a feature the file uses
            continue
        assert_optimal_means_checked(result)
        shown = " ".join(str(value) for _, value in check_rows(result))
        assert all(f.name in shown for f in result.failed_checks())  # the summary names each one
        if "not optimal: failed check(s)" in result.message:  # downgraded by the policy
            assert all(f.name in result.message for f in result.failed_checks())


def test_the_solve_table_names_the_failed_check_in_its_title_and_rows(cli) -> None:
    code, out, _ = cli("solve", PROBLEMS / "ocp" / "hang_glider.yaml", "--set", "method.intervals=10")
    assert code == 0
    assert "hang_glider on casadi: feasible (failed: max_defect_relative)" in out
    assert "failed check" in out and "tolerance 1e-06" in out
