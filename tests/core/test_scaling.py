"""Scaling by default (issue 25, item 4; :mod:`gamespec.ocp.scaling`): factors are powers of ten of
the magnitudes the guess, the fixed ends or the bounds give (1 within 10^±2), the NLP's variables and
defect rows are divided by them on both backends, and what comes back is the unscaled problem's
solution: objective and costates against the closed form of a minimum-energy transfer in large
units (the transfer of tests/pyomo/test_parity.py with every length multiplied by 1e4)."""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.ocp.scaling import power_of_ten
from gamespec.ocp.transcription import Transcription
from tests.conftest import PROBLEMS

LENGTH = 1e4
X0, V0 = 0.7 * LENGTH, -0.4 * LENGTH


def _transfer(scale: str = "auto") -> dict:
    return {
        "kind": "optimal_control",
        "name": "minimum_energy_transfer_in_large_units",
        "problem": {
            "states": {"x": {"initial": X0, "final": 0.0}, "v": {"initial": V0, "final": 0.0}},
            "controls": {"u": {}},
            "dynamics": {"x": "v", "v": "u"},
            "objective": {"lagrange": "0.5*u**2"},
            "time": {"final": 1.0},
        },
        "method": {"intervals": 10, "degree": 3, "scale": scale},
    }


@pytest.mark.parametrize(
    ("magnitude", "factor"),
    [(2.6e5, 1e5), (25600.0, 1e4), (50.0, 1.0), (0.02, 1.0), (1e-4, 1e-4), (0.0, 1.0), (np.inf, 1.0)],
)
def test_power_of_ten(magnitude: float, factor: float) -> None:
    assert power_of_ten(magnitude) == factor


def test_shuttle_factors_come_from_the_guess() -> None:
    """h from 260,000 ft to 80,000 ft and v from 25,600 ft/s: 10^round(log10(2.6e5)) and
    10^round(log10(2.56e4)); the angles (of order 1) and the controls keep 1."""
    tr = Transcription(gamespec.load(PROBLEMS / "ocp" / "shuttle_reentry.yaml"))
    found = tr.compiled_scaling
    states = dict(zip(tr.ocp.states, found.states, strict=True))
    assert states == {"h": 1e5, "phi": 1.0, "theta": 1.0, "v": 1e4, "gamma": 1.0, "psi": 1.0}
    assert list(found.controls) == [1.0, 1.0]
    assert found.warning == ""


def test_scale_none_and_a_warning_when_nothing_gives_a_magnitude() -> None:
    off = Transcription(gamespec.spec_from_dict(_transfer("none"))).compiled_scaling
    assert list(off.states) == [1.0, 1.0]
    data = _transfer()
    data["problem"]["states"]["y"] = {}  # no bound, no fixed end, a zero guess
    data["problem"]["dynamics"]["y"] = "0*u"
    found = Transcription(gamespec.spec_from_dict(data)).compiled_scaling
    assert "nothing gives y, u a magnitude" in found.warning  # u: unbounded, its guess 0


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_scaled_solution_is_the_closed_form(backend: str) -> None:
    """J* = 6x0² + 6x0v0 + 2v0², λ_x = 12x0 + 6v0, λ_v(t) = 6x0 + 4v0 - λ_x t (the costates from the
    defect multipliers, whose rows were divided by the state scales)."""
    result = gamespec.solve(gamespec.spec_from_dict(_transfer()), backend)
    assert result.status.value == "optimal", result.message
    assert result.metrics["scaling"]["states"] == {"x": 1e4, "v": 1e4}
    assert result.objective == pytest.approx(6 * X0**2 + 6 * X0 * V0 + 2 * V0**2, rel=1e-9)
    t = result.arrays["costate_time"]
    lam_x = 12 * X0 + 6 * V0
    np.testing.assert_allclose(result.costates["lambda_x"], lam_x, rtol=1e-8)
    np.testing.assert_allclose(
        result.costates["lambda_v"], 6 * X0 + 4 * V0 - lam_x * t, rtol=0, atol=1e-8 * LENGTH
    )
