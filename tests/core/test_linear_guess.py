"""The ``linear`` guess never starts where a boundary constraint's gradient vanishes (issue 27,
item 6): states free at both ends and unbounded start at 0, where ``x_0**2 + v_0**2 == 1`` has a
zero gradient and both backends stopped at a point of local infeasibility."""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.ocp.transcription import Transcription
from gamespec.result import Status

CIRCLE = {
    "kind": "optimal_control",
    "name": "start_on_circle",
    "problem": {
        "states": {"x": {}, "v": {}},
        "controls": {"u": {"lower": -1.0, "upper": 1.0}},
        "dynamics": {"x": "v", "v": "u"},
        "objective": {"lagrange": "u**2 + x**2"},
        "time": {"final": 1.0},
        "boundary_constraints": ["x_0**2 + v_0**2 == 1"],
    },
    "method": {"intervals": 10, "degree": 3},
}


def test_guess_is_moved_off_the_flat_point() -> None:
    spec = gamespec.spec_from_dict(CIRCLE)
    guess = Transcription(spec).guess(spec.problem.parameter_values())
    x0, v0 = guess.X[0, 0], guess.X[1, 0]
    assert np.hypot(2 * x0, 2 * v0) > 0.1  # the constraint's gradient (2 x_0, 2 v_0)


def test_guess_is_kept_where_the_gradient_does_not_vanish() -> None:
    data = {**CIRCLE, "problem": {**CIRCLE["problem"], "boundary_constraints": ["x_0 + v_0 == 1"]}}
    spec = gamespec.spec_from_dict(data)
    guess = Transcription(spec).guess(spec.problem.parameter_values())
    assert np.all(guess.X == 0.0)


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_solves_and_meets_the_constraint(backend: str) -> None:
    result = gamespec.solve(gamespec.spec_from_dict(CIRCLE), backend)
    assert result.status is Status.OPTIMAL, result.message
    assert result.states["x"][0] ** 2 + result.states["v"][0] ** 2 == pytest.approx(1.0, abs=1e-7)
