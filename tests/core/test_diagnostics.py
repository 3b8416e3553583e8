"""A NaN or an infinity names the file's expression and the time (issue 25, item 7), not an NLP row.

A speed ``sqrt(vx**2 + vy**2)`` is 0 at rest but its derivative ``vx / sqrt(vx**2 + vy**2)`` is 0/0
there: from a guess at rest (the linear guess between fixed rest states) IPOPT stops with
``Invalid_Number_Detected``; the message must name the definition and the state it is
differentiated in. ``log(y)`` at y = 0 is -inf: a value, named as the derivative of its state."""

from __future__ import annotations

import gamespec
from gamespec.ocp.diagnostics import Point, non_finite_report
from gamespec.ocp.transcription import Transcription
from gamespec.result import Status
from tests.conftest import PROBLEMS


def _at_rest() -> dict:
    return {
        "kind": "optimal_control",
        "name": "drag_from_rest",
        "problem": {
            "parameters": {"c": 0.1},
            "states": {
                "x": {"initial": 0.0, "final": 1.0},
                "y": {"initial": 0.0, "final": 0.0},
                "vx": {"initial": 0.0, "final": 0.0},
                "vy": {"initial": 0.0, "final": 0.0},
            },
            "controls": {"ax": {"lower": -2.0, "upper": 2.0}, "ay": {"lower": -2.0, "upper": 2.0}},
            "definitions": {"speed": "sqrt(vx**2 + vy**2)"},
            "dynamics": {"x": "vx", "y": "vy", "vx": "ax - c*speed*vx", "vy": "ay - c*speed*vy"},
            "objective": {"lagrange": "ax**2 + ay**2"},
            "time": {"final": 2.0},
        },
        "method": {"intervals": 10},
    }


def _start(spec: gamespec.OptimalControlSpec) -> tuple[Transcription, Point]:
    tr = Transcription(spec)
    params = tr.ocp.parameter_values()
    start = tr.guess(params)
    return tr, Point(start.X, start.U, start.T, tr.input_values(params), params)


def test_a_nan_derivative_at_the_start_names_the_definition_and_the_time() -> None:
    result = gamespec.solve(gamespec.spec_from_dict(_at_rest()), "casadi")
    assert result.status is Status.NUMERICAL_ERROR
    assert "definition speed (sqrt(vx**2 + vy**2)): its derivative in vx is not finite" in result.message
    assert "vx = 0, vy = 0" in result.message
    assert "row" not in result.message


def test_an_infinite_value_names_the_state_derivative() -> None:
    data = _at_rest()
    data["problem"]["definitions"] = {}
    data["problem"]["dynamics"] |= {"vx": "ax + log(y)", "vy": "ay"}
    tr, start = _start(gamespec.spec_from_dict(data))
    report = non_finite_report(tr, start)
    assert report is not None
    assert report.startswith("the derivative of state vx (ax + log(y)): its value is not finite")


def test_a_healthy_start_reports_nothing() -> None:
    tr, start = _start(gamespec.load(PROBLEMS / "ocp" / "shuttle_reentry.yaml"))
    assert non_finite_report(tr, start) is None
