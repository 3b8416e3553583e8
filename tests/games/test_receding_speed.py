"""What the chapter-7 receding horizon leaves out to run at the solver's pace (issue 29, item 2), each
against the route that does not leave it out: the OCP solution checks of every best response (the
run reports none of them), a verification response at the point a player has just answered (the
response it gave there), and IPOPT's default start where the file warm-starts it."""

from __future__ import annotations

import numpy as np
import pytest

from gamespec.games import equilibrium, receding_horizon
from gamespec.games.equilibrium import GameModel
from gamespec.loader import load
from gamespec.ocp.transcription import UNCHECKED
from gamespec.result import Status
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS

FILE = PROBLEMS / "ch7" / "asymmetric_obstacle.yaml"
SHORT = ["problem.parameters.Q=1", "receding_horizon.time_limit=0.4"]
"""Four steps of the Q = 1 run: both views, the pursuer's RCS transform in its own game."""


def _run(monkeypatch: pytest.MonkeyPatch | None = None, *overrides: str):
    spec = load(FILE, [*SHORT, *overrides])
    if monkeypatch is not None:
        monkeypatch.setattr(receding_horizon, "_unchecked", lambda model: model)
    return compile_spec(spec).solve()


def test_unchecked_responses_give_the_same_run(monkeypatch):
    """Every best response checked or not: the same trajectories, controls and solves to the last
    bit (the checks only judge a response, they never change it)."""
    unchecked = _run()
    checked = _run(monkeypatch)
    assert unchecked.metrics["solves"] == checked.metrics["solves"]
    for group in ("states", "controls"):
        a, b = getattr(unchecked, group), getattr(checked, group)
        assert a.keys() == b.keys()
        assert all(np.array_equal(a[k], b[k]) for k in a)
    assert unchecked.status == checked.status and unchecked.message == checked.message


def test_an_unchecked_response_says_so_and_claims_no_optimum():
    """A response solved without the checks has none, names them skipped, and is ``feasible``
    where the same solve checked is ``optimal`` with every check passed."""
    spec = load(FILE, SHORT)
    model = GameModel(spec)
    responder = model.responders[("evader", "evader")]
    responder.set_values(model.values("evader", "evader", dict(spec.problem.values.initial), 0.0))
    others = model.start("evader")
    checked = responder.respond(others)[1]
    responder.check_responses(False)
    unchecked = responder.respond(others)[1]
    assert checked.status is Status.OPTIMAL and all(checked.metrics["checks_passed"].values())
    assert unchecked.status is Status.FEASIBLE and not unchecked.checks
    assert unchecked.metrics["checks_skipped"] == {"solution_checks": UNCHECKED}
    assert UNCHECKED in unchecked.message
    np.testing.assert_allclose(unchecked.controls["v"], checked.controls["v"], atol=1e-7)


def test_a_verification_at_the_point_just_answered_reuses_that_response(monkeypatch):
    """The returned point of a Gauss–Seidel sweep holds the last player's response to the others'
    strategies there: the verification asks it again only when the point differs, and the gap it
    reports is the one a fresh solve there gives (to IPOPT's tolerance)."""
    spec = load(FILE, SHORT)
    model = GameModel(spec)
    state = dict(spec.problem.values.initial)
    reused = model.solve("evader", state, 0.0)
    solves = {name: r.solves for (view, name), r in model.responders.items() if view == "evader"}
    fresh = GameModel(spec)
    monkeypatch.setattr(equilibrium.BestResponder, "response_at", equilibrium.BestResponder.respond)
    again = fresh.solve("evader", state, 0.0)
    fresh_solves = {name: r.solves for (view, name), r in fresh.responders.items() if view == "evader"}
    assert reused.run.converged and again.run.converged
    assert fresh_solves == {"pursuer": solves["pursuer"], "evader": solves["evader"] + 1}
    assert reused.equilibrium.gap == pytest.approx(again.equilibrium.gap, abs=1e-7)


def test_warm_started_ipopt_reaches_the_default_starts_run():
    """The file's warm starts (the last multipliers, ``mu_init`` 1e-6) against IPOPT's default
    start: the same four steps, every game converged (a game may take a sweep more or less: its
    residual lands on the other side of the tolerance), the trajectories to IPOPT's tolerance."""
    warm = _run()
    cold = _run(None, "solver.options.casadi.ipopt={}")
    for name in warm.states:
        np.testing.assert_allclose(warm.states[name], cold.states[name], atol=1e-6)
    assert warm.metrics["all_converged"] and cold.metrics["all_converged"]
