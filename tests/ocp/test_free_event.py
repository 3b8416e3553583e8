"""Constraints at a free event time (issue 25, item 2; the ``free_event`` rewrite): a closed form
with the event time inside its bounds and one with it held at a bound, and the refusals."""

from __future__ import annotations

import pytest

import gamespec
from gamespec.errors import SpecError
from gamespec.loader import spec_from_dict
from tests.conftest import rest_to_rest

A, T = 1.0, 2.0


def _through(bounds: list[float]) -> dict:
    """min integral of u^2, x'' = u, rest to rest at x = 0 on [0, T], passing x = a at some free
    time t_e within ``bounds``."""
    event = {"free_event": {"bounds": bounds, "constraints": ["x == a"]}}
    return rest_to_rest(A, T) | {"transforms": [event], "method": {"intervals": 6, "degree": 3}}


def _energy(x: float, v: float, tau: float) -> float:
    """The least integral of u^2 taking x'' = u from rest at 0 to (x, v) in time tau (u linear in
    time): 12 x^2/tau^3 - 12 x v/tau^2 + 4 v^2/tau."""
    return 12 * x**2 / tau**3 - 12 * x * v / tau**2 + 4 * v**2 / tau


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_free_event_time_is_found_where_the_closed_form_puts_it(backend: str) -> None:
    """Each leg is a minimum-energy move; by the problem's symmetry under t -> T - t the best pass is
    at t_e = T/2 at rest, J* = 2 * 12 a^2/(T/2)^3 = 192 a^2/T^3, the fixed-time optimum at T/2."""
    result = gamespec.solve(spec_from_dict(_through([0.3, 1.9])), backend=backend)
    assert result.status == gamespec.Status.OPTIMAL, result.message
    assert result.metrics["event_time"] == pytest.approx(T / 2, abs=1e-6)
    assert result.objective == pytest.approx(192 * A**2 / T**3, rel=1e-8)


def test_event_time_held_at_its_bound_when_the_best_pass_is_outside() -> None:
    """With t_e in [1.3, 1.8] the pass is at 1.3 (the cost grows away from T/2), with the speed v
    there that minimizes the two legs' energies, a quadratic in v: the closed form
    min_v E(a, v, t_e) + E(a, -v, T - t_e)."""
    result = gamespec.solve(spec_from_dict(_through([1.3, 1.8])))
    assert result.status == gamespec.Status.OPTIMAL, result.message
    te = 1.3
    s = T - te
    # d/dv of the sum is linear: (-12a/te^2 + 8v/te) + (12a/s^2 + 8v/s) = 0
    v = (12 * A / te**2 - 12 * A / s**2) / (8 / te + 8 / s)
    # IPOPT relaxes bounds by 1e-8 (bound_relax_factor): t_e may sit that far below 1.3, where
    # the cost falls at ~50 per unit time (J' = dE/dt_e), so J within 1e-6 absolute
    assert result.metrics["event_time"] == pytest.approx(te, abs=1e-7)
    assert result.objective == pytest.approx(_energy(A, v, te) + _energy(A, -v, s), abs=1e-6)
    assert result.time[-1] == pytest.approx(T, abs=1e-9)


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        ({"bounds": [0.0, 1.0]}, "strictly inside the horizon"),
        ({"bounds": [1.5, 1.0]}, "bounds must be increasing"),
        ({"constraints": ["y == 1"]}, "y"),
    ],
)
def test_bad_free_events_are_refused_at_load(change: dict, reason: str) -> None:
    data = _through([0.3, 1.9])
    data["transforms"][0]["free_event"] |= change
    with pytest.raises(SpecError, match=reason):
        gamespec.solving.transformed(spec_from_dict(data))
