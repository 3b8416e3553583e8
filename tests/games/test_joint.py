"""``game.scheme: joint`` (:mod:`gamespec.games.joint`): the players' stacked KKT conditions solved at
once, checked against independent references.

- The scalar zero-sum LQ games of ``problems/ch7/scalar_lq_*.yaml``: the saddle value ``½ P(0) x0²``
  of the game's Riccati equation ``−Ṗ = 2aP + q − (1 − 1/γ²) P²``, ``P(T) = s``, integrated here
  with SciPy (tests/games/test_honest_equilibria.py derives it);
- the chapter-7 LQ pursuit-evasion file: its closed-form saddle (tests/games/test_lq_game.py);
- a nonzero-sum game of two minimizers: the open-loop Nash payoffs ``J_i = ½ s_i x(T)² + ½∫u_i²``
  with ``u_i = −s_i x(T)`` constant, ``x(T) = x0 / (1 + (s_1 + s_2) T)``;
- the homicidal chauffeur (box-bounded controls, a complementarity problem): best responses on
  the same file, which converge there (damped by 0.5).
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from gamespec.loader import load
from gamespec.result import Status
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS
from tests.games.test_honest_equilibria import NONZERO_SUM, riccati_value
from tests.games.test_lq_game import FILE as CH7
from tests.games.test_lq_game import expected

SCALAR = ["scalar_lq_saddle", "scalar_lq_three_sevenths"]
CHAUFFEUR = PROBLEMS / "ch7" / "homicidal_chauffeur.yaml"


@pytest.mark.parametrize("name", SCALAR)
def test_the_scalar_lq_games_reach_their_riccati_values_in_one_newton_step(name):
    """Within 1e-8 of the SciPy Riccati value, ``optimal`` with a passed gap check, in one Newton
    iteration (the stacked system is linear) and under a second of CPU for the solve."""
    spec = load(PROBLEMS / "ch7" / f"{name}.yaml")
    solver = compile_spec(spec)
    started = time.process_time()
    result = solver.solve()
    cpu = time.process_time() - started
    p = spec.problem.parameters
    want = riccati_value(p["a"], p["q"], p["s"], p["g2"], p["T"], spec.problem.states["x"].initial)
    assert result.status is Status.OPTIMAL, result.message
    assert abs(result.objective - want) <= 1e-8
    m = result.metrics
    assert m["solution_concept"] == "saddle" and m["information"] == "open_loop"
    assert m["checks_passed"]["saddle_gap"] and abs(m["saddle_gap"]) <= spec.game.tolerance
    run = m["best_response"]["pursuer"]
    assert run["scheme"] == "joint" and run["iterations"] == 1 and run["residual"] <= 1e-10
    assert cpu < 1.0


def test_the_three_sevenths_game_diverges_under_best_responses():
    """The same file by undamped Gauss–Seidel does not converge (the map multiplies the change by
    2.5 a sweep): what the joint scheme is for."""
    result = compile_spec(
        load(PROBLEMS / "ch7" / "scalar_lq_three_sevenths.yaml", ["game.scheme=gauss_seidel"])
    ).solve()
    assert result.status is not Status.OPTIMAL


def test_the_chapter_7_lq_file_reaches_its_closed_form_saddle():
    spec = load(CH7, ["game.scheme=joint"])
    result = compile_spec(spec).solve()
    want = expected(spec)
    assert result.status is Status.OPTIMAL, result.message
    assert result.objective == pytest.approx(want["payoff"], abs=1e-9)
    for name, value in (
        ("u1", want["u"][0]),
        ("u2", want["u"][1]),
        ("v1", want["v"][0]),
        ("v2", want["v"][1]),
    ):
        assert np.allclose(result.controls[name], value, atol=1e-8)


def test_a_nonzero_sum_game_reaches_its_open_loop_nash_payoffs(tmp_path):
    path = tmp_path / "nash.yaml"
    path.write_text(NONZERO_SUM.replace("scheme: gauss_seidel", "scheme: joint"))
    spec = load(path)
    result = compile_spec(spec).solve()
    p = spec.problem.parameters
    xT = 1.0 / (1 + (p["s1"] + p["s2"]) * p["T"])
    want = {
        "first": 0.5 * p["s1"] * xT**2 + 0.5 * p["T"] * (p["s1"] * xT) ** 2,
        "second": 0.5 * p["s2"] * xT**2 + 0.5 * p["T"] * (p["s2"] * xT) ** 2,
    }
    assert result.status is Status.OPTIMAL, result.message
    assert result.metrics["solution_concept"] == "open_loop_nash"
    for player, value in want.items():
        assert result.metrics["payoffs"][player] == pytest.approx(value, abs=1e-9)


def test_the_homicidal_chauffeur_agrees_with_best_responses():
    """Bounded turn rates (complementarity along the barrier path): the joint point and the
    converged best responses' share the payoff and the controls (the pedestrian's heading modulo
    2π: best responses land on either of two equal angles), and the joint point's gap (one best
    response per player there) passes."""
    joint = compile_spec(load(CHAUFFEUR, ["game.scheme=joint"])).solve()
    responses = compile_spec(load(CHAUFFEUR)).solve()
    tolerance = 1e-6
    assert joint.ok and joint.metrics["checks_passed"]["saddle_gap"]
    assert responses.metrics["best_response"]["car"]["converged"]
    assert joint.objective == pytest.approx(responses.objective, abs=10 * tolerance)
    assert np.max(np.abs(joint.controls["w"] - responses.controls["w"])) <= 1e-3
    heading = joint.controls["v"] - responses.controls["v"]
    assert np.max(np.abs(np.angle(np.exp(1j * heading)))) <= 1e-3, "the pedestrian's headings, modulo 2π"
    assert joint.metrics["solution_concept"] == "saddle"


def test_joint_needs_casadi():
    with pytest.raises(Exception, match="casadi"):
        load(CH7, ["game.scheme=joint", "game.backend=pyomo"])


@pytest.mark.slow
@pytest.mark.parametrize("weight", ["0", "1"])
def test_the_receding_horizon_of_chapter_7_agrees_with_best_responses(weight):
    """Algorithm 4 on ``asymmetric_obstacle.yaml`` for 3 s (each player its own game, the
    pursuer's RCS regularizer at Q = 1): every step's game by the joint scheme and by Gauss–Seidel
    best responses (which converge at each step there) drive the true system along the same path."""
    sets = ["receding_horizon.time_limit=3.0", f"problem.parameters.Q={weight}"]
    file = PROBLEMS / "ch7" / "asymmetric_obstacle.yaml"
    responses = compile_spec(load(file, sets)).solve()
    joint = compile_spec(load(file, [*sets, "game.scheme=joint"])).solve()
    assert responses.metrics["all_converged"] and joint.metrics["all_converged"]
    assert joint.metrics["steps"] == responses.metrics["steps"]
    assert max(np.max(np.abs(joint.states[k] - responses.states[k])) for k in responses.states) <= 1e-5
