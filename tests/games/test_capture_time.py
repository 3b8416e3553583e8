"""Games of degree (``time.final: free``): the capture time as payoff, decided by the ``hji`` backend's
minimum-time-to-capture value.

- A pursuer steering (ẋ, ẏ) in the unit box against an evader that cancels up to half of its
  x-speed, with a disk target of radius r: the minimum time to capture from (x, y) is the least τ
  with ``hypot((|x| − τ/2)⁺, (|y| − τ)⁺) ≤ r`` (the set captured within τ is the disk's Minkowski sum
  with [−τ/2, τ/2] × [−τ, τ]). The grid's times agree with it within a grid spacing at the slowest
  guaranteed speed (1/2), and the error falls with the spacing.
- The homicidal chauffeur (``problems/ch7/homicidal_chauffeur_capture_time.yaml``) at γ = 0.7 on
  both sides of Isaacs' barrier threshold ℓ/R = √(1−γ²) + γ·asin γ − 1: at ℓ = 0.15 escape (the
  capture time +∞, the captured set converged), at ℓ = 0.4 capture no sooner than the pedestrian's
  straight run away allows, (d₀ − ℓ)/(w(1 − γ)) (its distance falls at most at w(1 − γ) whatever the
  car does), less the grid's error.
- Best responses and the joint scheme refuse a game of degree with the reason; a capture time not
  reached within the bound, from a set that still grows, is undecided, never escape.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

from gamespec.errors import SpecError, UnsupportedFeature
from gamespec.loader import load
from gamespec.result import Status
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS

CHAUFFEUR = PROBLEMS / "ch7" / "homicidal_chauffeur_capture_time.yaml"
GAMMA = 0.7
BARRIER = math.sqrt(1 - GAMMA**2) + GAMMA * math.asin(GAMMA) - 1

BOX_GAME = """
kind: differential_game
name: box_pursuit_time
problem:
  parameters: {{r: 0.3}}
  states:
    x: {{lower: -1.0, upper: 1.0, initial: 0.4}}
    y: {{lower: -1.0, upper: 1.0, initial: 0.3}}
  dynamics: {{x: a + c, y: b}}
  players:
    pursuer: {{objective: minimize, controls: {{a: {{lower: -1, upper: 1}}, b: {{lower: -1, upper: 1}}}}}}
    evader: {{objective: maximize, controls: {{c: {{lower: -0.5, upper: 0.5}}}}}}
  capture: x**2 + y**2 <= r**2
  time: {{final: free, bounds: [0, 0.5]}}
solver: {{backend: hji, options: {{hji: {{nodes: {nodes}}}}}}}
"""


def box_capture_time(x: np.ndarray, y: np.ndarray, r: float = 0.3) -> np.ndarray:
    """The least τ with ``hypot((|x| − τ/2)⁺, (|y| − τ)⁺) ≤ r`` by bisection (the distance falls with τ)."""
    lo, hi = np.zeros_like(x), np.full_like(x, 10.0)
    for _ in range(60):
        mid = (lo + hi) / 2
        inside = np.hypot(np.maximum(abs(x) - mid / 2, 0), np.maximum(abs(y) - mid, 0)) <= r
        hi, lo = np.where(inside, mid, hi), np.where(inside, lo, mid)
    return hi


def _box(tmp_path, nodes):
    file = tmp_path / f"box{nodes}.yaml"
    file.write_text(textwrap.dedent(BOX_GAME.format(nodes=nodes)))
    return compile_spec(load(file)).solve()


def test_box_game_capture_time_is_the_closed_form(tmp_path):
    errors = {}
    for nodes in (41, 81):
        result = _box(tmp_path, nodes)
        gx, gy = np.meshgrid(result.arrays["grid_x"], result.arrays["grid_y"], indexing="ij")
        exact = box_capture_time(gx, gy)
        within = exact <= 0.45
        errors[nodes] = float(np.abs(result.arrays["capture_time"][within] - exact[within]).max())
        spacing = gx[1, 0] - gx[0, 0]
        assert errors[nodes] <= spacing / 0.5, errors
        assert np.isinf(result.arrays["capture_time"][exact > 0.5 + spacing / 0.5 * (1 + 1e-9)]).all()
        assert result.metrics["outcome"] == "capture" and result.metrics["captured"]
        assert abs(result.objective - box_capture_time(np.array(0.4), np.array(0.3))) <= spacing / 0.5
    assert errors[81] < errors[41] / 2, errors
    assert result.status is Status.OPTIMAL, result.message
    assert result.t_final == result.objective == result.metrics["capture_time"]
    assert result.metrics["payoffs"] == {"pursuer": result.objective, "evader": result.objective}


@pytest.fixture(scope="module")
def chauffeur():
    model = compile_spec(load(CHAUFFEUR))
    return {ell: model.solve({"l": ell}) for ell in (0.15, 0.4)}


def test_below_the_barrier_the_pedestrian_escapes(chauffeur):
    result = chauffeur[0.15]
    assert result.status is Status.OPTIMAL, result.message
    assert result.metrics["outcome"] == "escape" and not result.metrics["captured"]
    assert result.metrics["capture_time"] is None and result.objective == math.inf
    assert result.metrics["capture_region"]["converged"]
    assert "escape" in result.message


def test_above_the_barrier_the_car_captures_no_sooner_than_a_straight_run_allows(chauffeur):
    spec = load(CHAUFFEUR)
    result = chauffeur[0.4]
    assert result.status is Status.OPTIMAL, result.message
    assert result.metrics["outcome"] == "capture"
    region = result.metrics["capture_region"]
    spacing = (region["upper"][1] - region["lower"][1]) / (region["nodes"] - 1)
    w, gamma = spec.problem.parameters["w"], spec.problem.parameters["gamma"]
    x0, y0 = spec.problem.values.initial.values()
    straight_run = (math.hypot(x0, y0) - 0.4) / (w * (1 - gamma))
    assert straight_run - spacing / (w * (1 - gamma)) <= result.metrics["capture_time"] <= region["horizon"]
    assert result.metrics["capture_time"] == result.objective == result.t_final


def test_the_result_names_its_concept(chauffeur):
    for result in chauffeur.values():
        assert result.metrics["solution_concept"] == "saddle"  # the controls separate: Isaacs' condition
        assert result.metrics["information"] == "feedback"
        assert "minimum time to capture" in result.metrics["value_function"]
        assert result.metrics["checks_passed"]["capture_time_refinement"]


def test_a_set_still_growing_at_the_bound_is_undecided_not_escape():
    model = compile_spec(load(CHAUFFEUR, ["problem.time.bounds=[0, 1.0]"]))
    result = model.solve({"l": 0.4})
    assert result.status is Status.ITERATION_LIMIT
    assert result.metrics["outcome"] == "undecided" and "undecided" in result.message


@pytest.mark.parametrize("override", ["game.scheme=gauss_seidel", "game.scheme=joint"])
def test_open_loop_schemes_refuse_a_game_of_degree_with_the_reason(override):
    spec = load(CHAUFFEUR, ["solver.backend=best_response", override])
    with pytest.raises(UnsupportedFeature, match=r"value function.*hji"):
        compile_spec(spec)


def test_best_responses_refuse_an_avoid_set():
    spec = load(
        PROBLEMS / "ch7" / "homicidal_chauffeur_reduced.yaml",
        ["solver.backend=best_response", "problem.avoid=x**2 + (y - 1)**2 <= 0.04"],
    )
    with pytest.raises(UnsupportedFeature, match=r"problem\.avoid"):
        compile_spec(spec)


@pytest.mark.parametrize(
    ("override", "field"),
    [
        ("problem.payoff.mayer=x_f", "problem.payoff"),
        ("problem.capture=null", "problem.time.final"),
        ("problem.time.bounds=null", "problem.time"),
        ("problem.time.bounds=[2, 1]", "problem.time.bounds"),
    ],
)
def test_a_game_of_degree_is_checked_at_load(override, field):
    with pytest.raises(SpecError, match=field.replace(".", r"\.")):
        load(CHAUFFEUR, [override])
