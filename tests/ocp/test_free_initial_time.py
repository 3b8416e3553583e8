"""A free initial time (issue 25, item 2): ``time: {initial: free, initial_bounds: [...]}``, the
horizon a decision variable and ``t_0`` usable in Mayer and boundary terms, checked by closed forms."""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.errors import SpecError
from gamespec.loader import spec_from_dict


def _reach(lagrange: str, mayer: str = "0", sense: str = "minimize", control: dict | None = None) -> dict:
    """x' = u from x(t_0) = 0 to x(2) = 1 (the final time fixed), t_0 free in [0, 1.5]."""
    return {
        "kind": "optimal_control",
        "problem": {
            "states": {"x": {"initial": 0.0, "final": 1.0}},
            "controls": {"u": control or {}},
            "dynamics": {"x": "u"},
            "objective": {"sense": sense, "lagrange": lagrange, "mayer": mayer},
            "time": {"initial": "free", "initial_bounds": [0.0, 1.5], "final": 2.0},
        },
        "method": {"intervals": 10, "degree": 3},
    }


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_energy_plus_duration_picks_the_horizon_of_the_closed_form(backend: str) -> None:
    """min integral of (u^2 + 1): the constant u = 1/T costs 1/T + T, least at T = 1, so t_0 = 1
    and J* = 2; transversality at the free initial time, H(t_0) = dPhi/dt_0 = 0, holds."""
    result = gamespec.solve(spec_from_dict(_reach("u**2 + 1")), backend=backend)
    assert result.status == gamespec.Status.OPTIMAL, result.message
    assert result.objective == pytest.approx(2.0, rel=1e-9)
    assert result.metrics["design"]["t_0"] == pytest.approx(1.0, rel=1e-7)
    assert result.time[0] == pytest.approx(1.0, rel=1e-7)
    assert result.t_final == pytest.approx(2.0, abs=1e-12)
    assert np.allclose(result.controls["u"], 1.0, atol=1e-7)
    assert result.checks["hamiltonian_end_error"] < 1e-6


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_latest_start_in_the_mayer_term(backend: str) -> None:
    """max t_0 with |u| <= 1: the move by 1 takes at least 1, so t_0 = 2 - 1 = 1."""
    data = _reach("0", mayer="t_0", sense="maximize", control={"lower": -1.0, "upper": 1.0})
    result = gamespec.solve(spec_from_dict(data), backend=backend)
    assert result.status == gamespec.Status.OPTIMAL, result.message
    assert result.objective == pytest.approx(1.0, abs=1e-7)
    assert result.time[0] == pytest.approx(1.0, abs=1e-7)


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_time_dependent_cost_sees_the_shifted_time(backend: str) -> None:
    """min integral of (u^2 + t), t_0 in [0.5, 1.5]: with u = 1/T on [2 - T, 2] the cost is
    J(T) = 1/T + 2T - T^2/2, stationary where -1/T^2 + 2 - T = 0, a minimum at T = 1 (J'' = 1) with
    J = 2.5, below J(0.5) = 2.875 and J(1.5) = 2.54. Unshifted (t from 0) it would be 1/T + T^2/2,
    least 1.5 at the same T: the objective tells the two apart."""
    data = _reach("u**2 + t")
    data["problem"]["time"]["initial_bounds"] = [0.5, 1.5]
    result = gamespec.solve(spec_from_dict(data), backend=backend)
    assert result.status == gamespec.Status.OPTIMAL, result.message
    assert result.time[0] == pytest.approx(1.0, rel=1e-7)
    assert result.objective == pytest.approx(2.5, rel=1e-9)


def test_free_initial_time_needs_bounds() -> None:
    data = _reach("u**2 + 1")
    del data["problem"]["time"]["initial_bounds"]
    with pytest.raises(SpecError, match="needs initial_bounds"):
        spec_from_dict(data)
