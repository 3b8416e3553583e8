"""The open-loop Monte Carlo simulates the control that was solved (issue 28, item 2).

For a fixed control, ``E[x(t_f)] = x(t_f; ρ̂) + (E[x_sim(t_f; ρ)] - x_sim(t_f; ρ̂))``: the solution's
final state plus the effect of the spread on a re-simulation (for a zero-mean symmetric
uncertainty, ``½ x_ρρ Var(ρ) + O(δ⁴)``; zero where the state is linear in the parameter). The
expectation of the re-simulation is computed by Gauss quadrature over the distribution (Legendre
for a uniform, Hermite for a normal), not by sampling. So over every shipped file with
``uncertain:`` and a Monte Carlo, the sampled mean of each final state must sit there within
sampling error: a re-simulation that interpolated the control points otherwise than the
transcription holds them (a spline through all of them) misses the solution's final state by far
more wherever the control moves within an interval.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from tests.desensitize.helpers import NEW_FILES, file_solver, resimulate

SAMPLES = 300
SIGMAS = 4.0
"""How many standard errors of the sampled mean the mean may sit from its expectation."""
NODES = 24
"""Gauss nodes per uncertain parameter."""


def _rule(distribution, nominal: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights (summing to 1) of the parameter's distribution about ``nominal``."""
    if distribution.normal is not None:
        x, w = np.polynomial.hermite_e.hermegauss(NODES)
        return nominal + distribution.normal.std * x, w / w.sum()
    low, high = distribution.uniform_bounds(nominal)
    x, w = np.polynomial.legendre.leggauss(NODES)
    return 0.5 * (low + high) + 0.5 * (high - low) * x, w / w.sum()


def _shipped_uncertain() -> list:
    """Shipped desensitization files whose Monte Carlo draws an uncertain parameter."""
    chosen = []
    for path in NEW_FILES:
        data = yaml.safe_load(path.read_text())
        if data["problem"].get("uncertain") and data["transforms"][0]["desensitize"].get("monte_carlo"):
            chosen.append(path)
    return chosen


@pytest.mark.parametrize("path", _shipped_uncertain(), ids=lambda p: p.stem)
def test_open_loop_mean_is_the_solutions_final_state_plus_the_spread_effect(path) -> None:
    solver = file_solver(path, edit={"monte_carlo": {"samples": SAMPLES, "seed": 3, "tracking": False}})
    result = solver.solve()
    assert result.ok, result.message
    mc = result.metrics["monte_carlo"]
    (name, distribution), *others = solver.spec.problem.uncertain.items()
    assert not others, "one uncertain parameter per shipped file (a tensor rule otherwise)"
    nominal = result.parameters[name]
    nodes, weights = _rule(distribution, nominal)
    spread = resimulate(solver.spec, result, {name: nodes}).final @ weights
    at_nominal = resimulate(solver.spec, result, {name: np.array([nominal])}).final[:, 0]
    for index, state in enumerate(solver.spec.problem.states):
        expected = result.states[state][-1] + spread[index] - at_nominal[index]
        error = SIGMAS * mc["final_state_std"][state] / np.sqrt(SAMPLES)
        defect = 10 * (result.checks["max_defect"] or 0.0)
        assert mc["final_state_mean"][state] == pytest.approx(expected, abs=error + defect + 1e-9), state
