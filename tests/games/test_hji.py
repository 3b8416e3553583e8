"""The ``hji`` backend (capture regions as HJI value functions) against closed forms.

- A game whose pursuer steers (ẋ, ẏ) in the unit box against an evader that cancels up to half of
  its x-speed, with a disk target: the set captured within T is the disk's Minkowski sum with the
  box [−T/2, T/2] × [−T, T] (both ways the evader can act: separable and not); every node farther
  than one grid spacing from that set's edge is classified as the exact set says.
- The homicidal chauffeur in Isaacs' reduced coordinates (``problems/ch7/homicidal_chauffeur_reduced
  .yaml``) at γ = 0.7: Isaacs' barrier closes around the capture circle iff
  ℓ/R < √(1−γ²) + γ·asin γ − 1, so below that the captured set stops growing (all of it is captured
  within a bounded time and the rest escapes), and above it the car captures from everywhere (the
  set keeps growing with the horizon). Checked at ℓ = 0.15 and 0.4 in the default suite, and the
  threshold located by a sweep over ℓ in a slow test.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

from gamespec.loader import load
from gamespec.result import Status
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS

CHAUFFEUR = PROBLEMS / "ch7" / "homicidal_chauffeur_reduced.yaml"
GAMMA = 0.7
BARRIER = math.sqrt(1 - GAMMA**2) + GAMMA * math.asin(GAMMA) - 1
"""Isaacs' threshold on ℓ/R at γ = 0.7 (about 0.2569)."""

BOX_GAME = """
kind: differential_game
name: box_pursuit
problem:
  parameters: {{r: 0.3}}
  states:
    x: {{lower: -1.0, upper: 1.0}}
    y: {{lower: -1.0, upper: 1.0}}
  dynamics: {{x: "{x}", y: b}}
  players:
    pursuer: {{objective: minimize, controls: {{a: {{lower: -1, upper: 1}}, b: {{lower: -1, upper: 1}}}}}}
    evader: {{objective: maximize, controls: {{c: {{lower: {c_lower}, upper: 0.5}}}}}}
  capture: x**2 + y**2 <= r**2
  time: {{final: 0.5}}
solver: {{backend: hji, options: {{hji: {{nodes: 41}}}}}}
"""


@pytest.mark.parametrize(("x", "c_lower"), [("a + c", -0.5), ("a*(1 - c)", 0.0)], ids=["separable", "mixed"])
def test_box_game_is_the_minkowski_sum(tmp_path, x, c_lower):
    file = tmp_path / "box.yaml"
    file.write_text(textwrap.dedent(BOX_GAME.format(x=x, c_lower=c_lower)))
    result = compile_spec(load(file)).solve()
    r, horizon = 0.3, 0.5
    gx, gy = np.meshgrid(result.arrays["grid_x"], result.arrays["grid_y"], indexing="ij")
    outside = np.hypot(np.maximum(abs(gx) - horizon / 2, 0), np.maximum(abs(gy) - horizon, 0))
    spacing = gx[1, 0] - gx[0, 0]
    clear = abs(outside - r) > spacing * (1 + 1e-9)  # farther than one spacing from the exact edge
    captured = result.arrays["value"] <= 0
    assert np.array_equal(captured[clear], (outside <= r)[clear])
    assert result.status is Status.OPTIMAL, result.message


@pytest.fixture(scope="module")
def chauffeur():
    model = compile_spec(load(CHAUFFEUR))
    return {ell: model.solve({"l": ell}) for ell in (0.15, 0.4)}


def test_the_barrier_threshold_lies_between_the_two_cases():
    assert 0.15 < BARRIER < 0.4


def test_below_the_barrier_the_capture_region_stops_growing(chauffeur):
    region = chauffeur[0.15].metrics["capture_region"]
    assert region["area"] == region["area_at_half_horizon"]
    assert region["fraction"] < 0.05


def test_above_the_barrier_the_capture_region_keeps_growing(chauffeur):
    below, above = (chauffeur[ell].metrics["capture_region"] for ell in (0.15, 0.4))
    cell = ((above["upper"][0] - above["lower"][0]) / (above["nodes"] - 1)) ** 2
    assert above["area"] - above["area_at_half_horizon"] > 20 * cell
    assert above["area"] > 5 * below["area"]


def test_value_function_result(chauffeur, tmp_path):
    from gamespec.games.plotting import plot_game

    result = chauffeur[0.15]
    assert result.metrics["solution_concept"] == "value_function"
    assert result.metrics["information"] == "feedback"
    assert result.arrays["value"].shape == (61, 61)
    assert result.metrics["checks_passed"]["capture_region_refinement"] == (result.status is Status.OPTIMAL)
    paths = plot_game(result, tmp_path)
    assert [p.name for p in paths] == ["capture_region.png"] and paths[0].stat().st_size > 0


def test_capture_field_is_checked(tmp_path):
    file = tmp_path / "bad.yaml"
    file.write_text(CHAUFFEUR.read_text().replace("x**2 + y**2 <= l**2", "x**2 + z <= l"))
    with pytest.raises(Exception, match="capture"):
        load(file)


@pytest.mark.slow
def test_the_switch_over_l_is_at_the_barrier_within_the_grid():
    """On [−2, 2]² with 81 nodes (spacing 0.05) and T = 6: every ℓ whose captured set stops growing
    lies below every ℓ whose set keeps growing, and Isaacs' threshold is within one spacing of the
    switch."""
    spacing = 0.05
    model = compile_spec(
        load(
            CHAUFFEUR,
            [
                "problem.time.final=6.0",
                "solver.options.hji.nodes=81",
                "solver.options.hji.lower=[-2,-2]",
                "solver.options.hji.upper=[2,2]",
            ],
        )
    )
    growing = {}
    for ell in np.arange(0.20, 0.345, 0.02):
        region = model.solve({"l": float(ell)}).metrics["capture_region"]
        growing[float(ell)] = region["area"] > region["area_at_half_horizon"]
    stops = [ell for ell, grows in growing.items() if not grows]
    grows = [ell for ell, grows in growing.items() if grows]
    assert stops and grows and max(stops) < min(grows), growing
    assert max(stops) - spacing <= BARRIER <= min(grows) + spacing, growing


def test_games_it_cannot_solve_are_refused_with_the_reason(tmp_path):
    from gamespec_levelset.hji import HJIBackend

    five_states = load(PROBLEMS / "ch7" / "homicidal_chauffeur.yaml")
    assert "two states" in HJIBackend().unsupported(five_states)
    file = tmp_path / "timed.yaml"
    file.write_text(CHAUFFEUR.read_text().replace("- w + gamma*w*cos(psi)", "- w*(1 + t) + gamma*w*cos(psi)"))
    assert "autonomous" in HJIBackend().unsupported(load(file))
