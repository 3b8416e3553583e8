"""Iterative LQ games (:mod:`gamespec.games.iterative_lq`) against independent references.

- On linear-quadratic games the discrete game is itself LQ: one classical Runge–Kutta step of
  ``ẋ = A x + B u`` with ``u`` held is ``x⁺ = A_d x + B_d u`` with ``A_d = Σ_{j≤4} (hA)^j / j!`` and
  ``B_d = h Σ_{j≤3} (hA)^j / (j+1)! B`` (computed here with NumPy), the stage costs are ``h`` times
  the running weights, and its feedback Nash equilibrium is Başar & Olsder's discrete coupled
  Riccati recursion (:func:`gamespec.games.feedback.discrete_feedback_nash`): iterative LQ must
  reproduce its gains and values. As the steps shrink both approach the continuous coupled Riccati
  solution (``game.information: feedback`` on the same file).
- On the nonlinear unicycle game (``problems/ch7/unicycle_pursuit_evasion.yaml``) each player's
  feedback strategy must be locally a best response: with the other player on its feedback law,
  deviations ``u_i = law_i + ε d`` of the player's controls change its payoff by ``O(ε²)`` in its
  favour's opposite (no first-order gain, no second-order gain). The closed loop is simulated here
  with NumPy from the file's dynamics.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gamespec.games.expressions import game_expressions
from gamespec.games.feedback import LQPlayer, discrete_feedback_nash
from gamespec.games.iterative_lq import DiscreteGame, iterative_lq
from gamespec.loader import load
from gamespec.result import Status
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS

SADDLE = PROBLEMS / "ch7" / "scalar_lq_saddle.yaml"
UNICYCLE = PROBLEMS / "ch7" / "unicycle_pursuit_evasion.yaml"


def _rk4_matrices(A: np.ndarray, B: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    n = A.shape[0]
    powers = [np.linalg.matrix_power(h * A, j) for j in range(5)]
    A_d = sum(powers[j] / math.factorial(j) for j in range(5))
    B_d = h * sum(powers[j] / math.factorial(j + 1) for j in range(4)) @ B
    return A_d.reshape(n, n), B_d


@pytest.mark.parametrize("steps", [20, 40])
def test_on_an_lq_game_it_reproduces_the_discrete_coupled_riccati_solution(steps):
    spec = load(SADDLE)
    p = spec.problem.parameters
    game = DiscreteGame(spec, game_expressions(spec), second_order=False).bind(p)
    solution = iterative_lq(game, steps, np.zeros((steps, 2)), 1e-12, 20)
    assert solution.converged and solution.iterations <= 2
    h = p["T"] / steps
    A_d, B_d = _rk4_matrices(np.array([[p["a"]]]), np.array([[1.0, 1.0]]), h)
    q = np.array([[p["q"]]])
    players = [
        LQPlayer(
            "pursuer",
            slice(0, 1),
            h * q,
            np.zeros((1, 2)),
            h * np.diag([1.0, -p["g2"]]),
            np.array([[p["s"]]]),
        ),
        LQPlayer(
            "evader",
            slice(1, 2),
            -h * q,
            np.zeros((1, 2)),
            -h * np.diag([1.0, -p["g2"]]),
            -np.array([[p["s"]]]),
        ),
    ]
    reference = discrete_feedback_nash([A_d] * steps, [B_d] * steps, players, np.array([1.0]))
    assert np.allclose(solution.P, reference.K, atol=1e-10)
    assert np.allclose(solution.costs, reference.values, atol=1e-10)


def test_its_value_approaches_the_continuous_feedback_saddle_as_the_steps_shrink():
    """The rectangle rule's O(h) error: halving h about halves the distance to the coupled
    Riccati value of ``game.information: feedback`` on the same (LQ) file."""
    spec = load(SADDLE)
    continuous = compile_spec(load(SADDLE, ["game.information=feedback"])).solve().objective
    errors = []
    for steps in (50, 100):
        game = DiscreteGame(spec, game_expressions(spec), False).bind(spec.problem.parameters)
        errors.append(abs(iterative_lq(game, steps, np.zeros((steps, 2)), 1e-12, 20).costs[0] - continuous))
    assert errors[1] < 0.6 * errors[0] and errors[1] < 0.05


def _closed_loop(result, p, player: int, deviation: np.ndarray) -> float:
    """The payoff J when both players follow their feedback laws but ``player`` adds
    ``deviation`` (K × its controls) to its own: RK4 of the file's dynamics in NumPy."""
    times = result.time
    h = times[1] - times[0]
    names = ["xp", "yp", "th", "xe", "ye"]
    controls = ["w", "v1", "v2"]
    own = [[0], [1, 2]][player]
    X = np.array([result.states[n] for n in names]).T
    U = np.array([result.controls[c] for c in controls]).T
    gains = np.array([result.metrics["gains"][c] for c in controls]).transpose(1, 0, 2)

    def f(x, u):
        return np.array([np.cos(x[2]), np.sin(x[2]), u[0], u[1], u[2]])

    x = X[0].copy()
    cost = 0.0
    for k in range(len(U)):
        u = U[k] - gains[k] @ (x - X[k])
        u[own] += deviation[k]
        cost += h * 0.5 * (p["r"] * u[0] ** 2 - p["q"] * (u[1] ** 2 + u[2] ** 2))
        k1 = f(x, u)
        k2 = f(x + h / 2 * k1, u)
        k3 = f(x + h / 2 * k2, u)
        k4 = f(x + h * k3, u)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return cost + 0.5 * p["s"] * ((x[0] - x[3]) ** 2 + (x[1] - x[4]) ** 2)


@pytest.mark.parametrize("quadratization", ["second_order", "gauss_newton"])
def test_on_a_nonlinear_game_each_feedback_strategy_is_locally_a_best_response(quadratization):
    spec = load(UNICYCLE, ["game.information=feedback", f"game.iterative_lq={quadratization}"])
    result = compile_spec(spec).solve()
    assert result.status is Status.OPTIMAL, result.message
    assert result.metrics["solution_concept"] == "feedback_saddle"
    assert result.metrics["method"] == "iterative_lq" and result.metrics["checks_passed"]["saddle_gap"]
    p = spec.problem.parameters
    K = len(result.control_time)
    nominal = _closed_loop(result, p, 0, np.zeros(K))
    assert nominal == pytest.approx(result.objective, abs=1e-10)
    rng = np.random.default_rng(7)
    eps = 1e-3
    for player, width, sense in ((0, 1, 1.0), (1, 2, -1.0)):
        for _ in range(3):
            d = rng.standard_normal((K, width))
            up, down = (_closed_loop(result, p, player, s * eps * d) for s in (1, -1))
            slope = (up - down) / (2 * eps)
            assert abs(slope) <= 1e-6, (player, slope)
            assert sense * (up - nominal) >= -1e-12 and sense * (down - nominal) >= -1e-12
