"""Issue 27, item 3: a file's text is parsed when the problem is compiled, never when the compiled
model solves. Every evaluation of an expression's text goes through the grammar's tree walker
(:func:`gamespec.symbolic.grammar.expression` and ``relation``, whatever module imports them), so
the walker is made to raise and the compiled model must still solve: the first solve after
compile, again, and again with new parameter values (whose checks take the walks kept at load,
:class:`gamespec.symbolic.grammar.Deferred`), each answer the one a fresh compile gives."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gamespec.errors import ExpressionError, SpecError
from gamespec.loader import load, spec_from_dict
from gamespec.result import Result
from gamespec.solving import compile_spec
from gamespec.symbolic import canonical, grammar
from tests.conftest import PROBLEMS, rest_to_rest
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
    """The compiled model's solves walk no text, the first included: the checks' functions are
    built at compile (:func:`gamespec.ocp.compiled_checks.prepare`), and the RCS transform's
    restarts are built once per inverse data (``RcsData.starting_points``)."""
    compiled = compile_spec(load(path, ["method.intervals=10"]))
    _refuse_parsing(monkeypatch)
    first = compiled.solve()
    assert first.status.ok, first.message
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


def _event_spec(a: float) -> dict:
    """A rest-to-rest double integrator through ``x(1) = sqrt(a)`` (an ``at:`` event) with a
    boundary constraint at a fixed time (``v(t=1.5)``)."""
    at = [{"time": 1.0, "constraints": ["x == sqrt(a)"]}]
    spec = rest_to_rest(a, 2.0, at=at, boundary_constraints=["v(t=1.5) <= a + 10"])
    return spec | {"name": "through_a_point", "method": {"intervals": 10, "degree": 3}}


def _refined_event_spec(a: float) -> dict:
    """:func:`_event_spec` made nonlinear (``v' = u - 2 sin(x) + w``, ``w`` a grid input whose
    default names ``a``; a definition in the running cost) with ``x`` free at the end, a boundary
    constraint over the end values (the ``linear`` guess's flat-gradient check reads it), a chained
    path constraint with numbers outside and ``h`` refinement: two refined meshes, each with the
    ``at:`` event and ``v(t=1.5)``."""
    spec = _event_spec(a)
    problem = spec["problem"]
    problem["states"]["x"] = {"initial": 0.0}
    problem["inputs"] = {"w": {"default": "0.1*a*tau"}}
    problem["dynamics"]["v"] = "u - 2*sin(x) + w"
    problem["definitions"] = {"e": "v**2"}
    problem["objective"]["lagrange"] = "u**2 + 0.1*e"
    problem["boundary_constraints"].append("x_f**2 + v_0**2 == 0.04")
    problem["path_constraints"] = ["-2 <= v + a*0 <= 2"]
    spec["method"]["refine"] = {"strategy": "h", "tolerance": 1e-12, "max_iterations": 2}
    return spec


CASES = {
    "bryson_denham": (
        lambda: load(PROBLEMS / "ocp" / "bryson_denham.yaml", ["method.intervals=10"]),
        {"l": 0.12},
    ),
    "feedback_game": (
        lambda: load(
            PROBLEMS / "ch7" / "unicycle_pursuit_evasion.yaml",
            ["game.information=feedback", "method.intervals=5"],
        ),
        {"q": 5.0},
    ),
    "at_event": (lambda: spec_from_dict(_event_spec(0.49)), {"a": 0.25}),
    "refined_mesh": (lambda: spec_from_dict(_refined_event_spec(0.49)), {"a": 0.25}),
    "hji_chauffeur": (
        lambda: load(
            PROBLEMS / "ch7" / "homicidal_chauffeur_capture_time.yaml", ["solver.options.hji.nodes=21"]
        ),
        {"l": 0.3},
    ),
    "desensitized": (
        lambda: load(
            PROBLEMS / "ch6" / "zermelo_fixed_final_sensitivity.yaml",
            ["transforms.0.desensitize.monte_carlo.samples=50", "method.intervals=10"],
        ),
        {"s1_final": 0.04},
    ),
}


def _history(result: Result) -> np.ndarray:
    """Each mesh's size, degree, iterations, objective and defect (NaN where its re-integration
    overflows; :mod:`gamespec.compiling.refinement`), a row per mesh."""
    keys = ("intervals", "max_degree", "iterations", "objective", "max_defect_relative")
    return np.array([[entry[k] for k in keys] for entry in result.metrics["refinement"]], dtype=float)


def _same_history(mine: Result, theirs: Result) -> bool:
    return np.array_equal(_history(mine), _history(theirs), equal_nan=True)


@pytest.mark.parametrize("case", list(CASES))
def test_first_solve_and_a_solve_at_new_values_walk_no_text(monkeypatch, case):
    """Compiled, the model solves first, then at new parameter values (warm-started from the first,
    as a re-solve is), with the walker refused; both answers equal those of the same two solves of
    a fresh compile with the walker allowed, to the bit."""
    spec_of, new = CASES[case]
    compiled = compile_spec(spec_of())
    with monkeypatch.context() as patched:
        _refuse_parsing(patched)
        solved = [compiled.solve(), compiled.solve(parameters=new)]
    reference = compile_spec(spec_of())
    fresh = [reference.solve(), reference.solve(parameters=new)]
    for mine, theirs in zip(solved, fresh, strict=True):
        assert mine.status == theirs.status and mine.status.ok, mine.message
        assert mine.message == theirs.message
        assert mine.objective == theirs.objective or (
            math.isinf(mine.objective) and math.isinf(theirs.objective)
        )
    assert solved[1].objective != solved[0].objective
    if case == "refined_mesh":
        assert all(_same_history(m, t) for m, t in zip(solved, fresh, strict=True))
        assert all(len(_history(r)) == 3 for r in solved)


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_adaptive_mesh_refinement_walks_no_text(monkeypatch, backend):
    """The hyper-sensitive problem's hp refinement (three meshes here) builds each mesh's model from
    the problem the compiled model parsed (its kept walks taken again, :meth:`~gamespec.ocp.symbolic.
    SymbolicOcp._keep`): with the walker refused, the same meshes, iterations and objectives, to the
    bit, as a fresh compile with the walker allowed."""
    sets = [f"solver.backend={backend}", "method.refine.max_iterations=2"]
    path = PROBLEMS / "ocp" / "hyper_sensitive.yaml"
    compiled = compile_spec(load(path, sets))
    with monkeypatch.context() as patched:
        _refuse_parsing(patched)
        refined = compiled.solve()
    fresh = compile_spec(load(path, sets)).solve()
    assert refined.status == fresh.status and refined.objective == fresh.objective
    assert _same_history(refined, fresh) and len(_history(refined)) == 3
    assert np.array_equal(refined.states["x"], fresh.states["x"])


def test_a_chained_constraint_with_a_parameter_outside_is_refused_by_field():
    """The outer terms of a chained constraint are numbers (:func:`gamespec.symbolic.grammar.
    relation`); one that names a parameter is refused at load with the field and the reason, as
    its SymPy check says (the kept walk's refusal of a parameter's value, a ``ValueError``, once
    escaped as ``problem: depends on a parameter's value``), so no solve walks it."""
    for where, text in [("path_constraints", "-a <= v <= a"), ("boundary_constraints", "-a <= x_f <= 2*a")]:
        with pytest.raises(SpecError) as refused:
            spec_from_dict(rest_to_rest(0.3, 2.0, **{where: [text]}))
        assert refused.value.field == f"problem.{where}.0"
        assert "outer terms of a chained constraint must be numbers" in str(refused.value)
    assert grammar.kept_relation("-a <= x <= a", ["a", "x"]) is None


def test_the_rcs_plot_of_a_saved_result_walks_no_text(monkeypatch, tmp_path):
    """The RCS figures of a saved Result (the Fig. 6.6 map included) parse no text."""
    from gamespec.plotting import plot_result

    result = Result.load(PROBLEMS.parent / "tests" / "data" / "results" / "rcs_single_obstacle")
    _refuse_parsing(monkeypatch)
    paths = plot_result(result, tmp_path)
    assert any(p.name.endswith("_sensitivity_map.png") for p in paths)


def test_a_refusal_at_new_values_reads_as_the_text_walk_says(monkeypatch):
    """``sqrt(a)`` at a = -1 is refused by the kept walk with the message and field a fresh load
    (every kept walk forgotten: the text walked) gives."""
    compiled = compile_spec(spec_from_dict(_event_spec(0.49)))
    with monkeypatch.context() as patched:
        _refuse_parsing(patched)
        with pytest.raises(SpecError) as kept:
            compiled.solve(parameters={"a": -1.0})
    canonical._KEPT.clear()
    grammar._kept_value.cache_clear()
    with pytest.raises(SpecError) as walked:
        spec_from_dict(_event_spec(-1.0))
    assert str(kept.value) == str(walked.value) and "not real" in str(kept.value)


TEXTS = [
    "sqrt(a) + x",
    "log(a - 1)*x + exp(a)",
    "x/(a - 2) + a**0.5",
    "atan2(a, a - 1) + sqrt(x*a)",
    "1e300*a*a",
]
VALUES = [-1.0, 0.0, 1.0, 2.0, 3.0, 1e200]


@pytest.mark.parametrize("text", ["-1 <= x*a <= 2", "x >= sqrt(a)", "log(a) == x", "2 >= x*a >= 1e-3"])
def test_kept_relation_is_the_float_walk(text):
    """A kept constraint (:func:`gamespec.symbolic.grammar.kept_relation`) at each value of ``a``
    gives the float walk's relation, or its refusal with the same message and column."""
    kept = grammar.kept_relation(text, ["a", "x"])
    assert kept is not None
    for a in VALUES:
        values = {"a": a, "x": 0.5}
        try:
            expected = grammar.relation(text, values, grammar.FLOATS)
        except ExpressionError as err:
            with pytest.raises(ExpressionError) as found:
                grammar.taken_relation(kept, values, text)
            assert (str(found.value), found.value.column) == (str(err), err.column)
        else:
            assert grammar.taken_relation(kept, values, text) == expected


@pytest.mark.parametrize("text", TEXTS)
def test_kept_walk_refuses_and_computes_as_the_float_walk(text):
    """A kept walk (:func:`gamespec.symbolic.grammar.kept_expression`) at each value of ``a`` gives
    the float walk's value, or its refusal with the same message and column."""
    kept = grammar.kept_expression(text, ["a", "x"])
    for a in VALUES:
        values = {"a": a, "x": grammar.unknown("x")}
        try:
            expected = grammar.expression(text, values, grammar.FLOATS)
        except ExpressionError as err:
            with pytest.raises(ExpressionError) as found:
                grammar.taken(kept, values, text)
            assert (str(found.value), found.value.column) == (str(err), err.column)
        else:
            assert grammar.taken(kept, values, text) == expected


def test_kept_guess_profiles_equal_the_text_walk():
    """The guess's expressions kept at transcription give the text walk's profile to the bit."""
    from gamespec.ocp.checks import ARRAYS
    from gamespec.ocp.transcription import Transcription

    spec = load(PROBLEMS / "ch6" / "zermelo_fixed_final_sensitivity.yaml")
    tr = Transcription(spec)
    params = spec.problem.parameter_values()
    start = tr.guess(params)
    tau = tr.grid.eval_tau
    walked = grammar.expression(spec.guess.controls["u"], dict(params) | {"tau": tau}, ARRAYS)
    assert np.array_equal(start.U[0], np.broadcast_to(walked, tau.shape))
