"""Issue 27, item 3: a file's text is parsed when the problem is compiled, never when the compiled
model solves. Every evaluation of an expression's text goes through the grammar's tree walker
(:func:`gamespec.symbolic.grammar.expression` and ``relation``, whatever module imports them), so
the walker is made to raise and the compiled model must still solve, twice."""

from __future__ import annotations

import pytest

from gamespec.loader import load, spec_from_dict
from gamespec.solving import compile_spec
from gamespec.symbolic import grammar
from tests.conftest import PROBLEMS
from tests.flowfield.test_stages import _spec


def _refuse_parsing(monkeypatch: pytest.MonkeyPatch) -> None:
    def refused(self: object, text: str, *args: object) -> None:
        raise AssertionError(f"an expression's text was parsed at solve time: {text!r}")

    monkeypatch.setattr(grammar._Walker, "__init__", refused)


def test_iterative_lq_games_solve_without_parsing_text(monkeypatch):
    """The feedback game of a non-LQ file (iterative LQ games): its discrete game is built from the
    expressions parsed at compile (:mod:`gamespec.games.expressions`), the first solve included."""
    path = PROBLEMS / "ch7" / "unicycle_pursuit_evasion.yaml"
    compiled = compile_spec(load(path, ["game.information=feedback", "method.intervals=5"]))
    _refuse_parsing(monkeypatch)
    first = compiled.solve()
    assert first.status.ok and first.metrics["method"] == "iterative_lq", first.message
    again = compiled.solve()
    assert again.status == first.status
    assert again.objective == pytest.approx(first.objective, rel=1e-12)


@pytest.mark.parametrize(
    "path",
    [PROBLEMS / "ocp" / "bryson_denham.yaml", PROBLEMS / "ch6" / "rcs_single_obstacle.yaml"],
    ids=["optimal_control", "rcs_transform"],
)
def test_an_optimal_control_problem_solves_again_without_parsing_text(monkeypatch, path):
    """After the first solve (which builds the compiled checks on first use, from the text) a
    re-solve of the compiled model walks no text: the checks evaluate the end-point terms by a
    compiled function (:func:`gamespec.ocp.compiled_checks.end_terms`), and the RCS transform's
    restarts are built once per inverse data (``RcsData.starting_points``)."""
    compiled = compile_spec(load(path, ["method.intervals=10"]))
    first = compiled.solve()
    assert first.status.ok, first.message
    _refuse_parsing(monkeypatch)
    again = compiled.solve()
    assert again.status.ok, again.message


def test_a_flow_field_game_solves_again_without_parsing_text(monkeypatch):
    """The staged chapter-5 chain (:mod:`gamespec.flowfield.transform`): each stage's flow,
    players and ε are parsed once (at load) and re-evaluated at new parameter values by
    substitution, here a new noise level that re-solves the covariance game."""
    compiled = compile_spec(spec_from_dict(_spec()))
    _refuse_parsing(monkeypatch)
    first = compiled.solve()
    assert "capture_time" in first.metrics, first.message
    noisier = compiled.solve(parameters={"noise": 0.1})
    assert noisier.objective > first.objective
