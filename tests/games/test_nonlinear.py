"""The homicidal chauffeur (``problems/ch7/homicidal_chauffeur.yaml``): no closed form, so the
check is the definition of an open-loop equilibrium. A fixed point of the damped iteration,
``s = (1 − w) s + w BR(s)``, is a fixed point of the best responses themselves, ``s = BR(s)``: each
player's strategy is its best response to the other's."""

from __future__ import annotations

import numpy as np

from gamespec.loader import load
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS

FILE = PROBLEMS / "ch7" / "homicidal_chauffeur.yaml"


def test_damped_fixed_point_is_a_pair_of_mutual_best_responses():
    spec = load(FILE)
    solver = compile_spec(spec)
    result = solver.solve()
    run = result.metrics["best_response"]["car"]
    assert result.ok and run["converged"], result.message
    model = solver.compiled.model
    strategies = {
        name: np.array([result.controls[c] for c in player.controls])
        for name, player in spec.problem.players.items()
    }
    bound = spec.game.tolerance / spec.game.damping + 1e-5
    for (_, name), responder in model.responders.items():
        others = {k: v for k, v in strategies.items() if k != name}
        response, report = responder.respond(others)
        assert report.ok
        assert np.linalg.norm(response - strategies[name]) <= bound
        assert abs(report.objective - result.objective) < 1e-5
