"""Measurements in multi-phase files (issue 25): each phase's ``measurements:`` adds its
least-squares term to the one lowered problem, on the copies of the phase (and piece) that holds
each time; checked by recovering known decay rates from exact synthetic data across two phases."""

from __future__ import annotations

import math

import pytest

import gamespec
from gamespec.errors import SpecError
from gamespec.loader import spec_from_dict

RATES = {"a": 0.7, "b": 1.6}
"""The decay rates that generate the data: x' = -a x in the first phase, -b x in the second."""


def _decay() -> dict:
    """x(0) = 2 decays at rate a for one time unit, then at rate b for 1.5; x is measured four
    times in each phase (and 3 x once in the second, an expression of the state)."""
    a, b = RATES["a"], RATES["b"]
    first = [0.25, 0.5, 0.75, 1.0]
    second = [1.3, 1.7, 2.1, 2.5]
    x1 = [2 * math.exp(-a * t) for t in first]
    x2 = [2 * math.exp(-a) * math.exp(-b * (t - 1.0)) for t in second]
    return {
        "kind": "multiphase_optimal_control",
        "problem": {
            "design": {"a": {"lower": 0.0, "upper": 5.0, "guess": 1.0}, "b": {"lower": 0.0, "upper": 5.0}},
            "states": {"x": {"initial": 2.0}},
            "dynamics": {"x": "-a*x"},
            "phases": [
                {
                    "name": "slow",
                    "duration": 1.0,
                    "measurements": {"times": first, "values": {"x": x1}},
                },
                {
                    "name": "fast",
                    "duration": 1.5,
                    "dynamics": {"x": "-b*x"},
                    "intervals": 16,
                    "measurements": {
                        "times": second,
                        "values": {"x": x2, "3*x": [3 * v for v in x2]},
                        "weights": {"3*x": [0.0, 0.0, 1.0, 0.0]},
                    },
                },
            ],
        },
        "method": {"intervals": 8, "degree": 4},
    }


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_two_phase_fit_recovers_the_rates_that_made_the_data(backend: str) -> None:
    """Exact data: the fit is the generating rates (to the collocation error) with a zero misfit;
    the second phase has its own 16 intervals (two pieces of the common 8), so its times fall on
    two different copies of the state."""
    result = gamespec.solve(spec_from_dict(_decay()), backend=backend)
    assert result.status == gamespec.Status.OPTIMAL, result.message
    for name, rate in RATES.items():
        assert result.metrics["design"][name] == pytest.approx(rate, rel=1e-6)
    assert result.objective == pytest.approx(0.0, abs=1e-10)


def test_the_lowered_problem_holds_one_measurements_block_over_the_phase_copies() -> None:
    spec = spec_from_dict(_decay())
    lowered = gamespec.solving.transformed(spec)
    data = lowered.problem.measurements
    assert data is not None
    assert len(data.times) == 4 + 4 * 2
    assert set(data.values) == {"x__slow", "x__fast__0", "x__fast__1", "3*x__fast__0", "3*x__fast__1"}
    assert all(0.0 <= t <= 1.0 for t in data.times)


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        ({"duration": {"value": "free", "bounds": [0.5, 2.0]}}, "every duration up to"),
        ({"measurements": {"times": [1.5], "values": {"x": [1.0]}}}, "outside the phase"),
    ],
)
def test_measurements_at_times_the_lowering_cannot_place_are_refused(change: dict, reason: str) -> None:
    data = _decay()
    data["problem"]["phases"][0] |= change
    with pytest.raises(SpecError, match=reason):
        spec_from_dict(data)
