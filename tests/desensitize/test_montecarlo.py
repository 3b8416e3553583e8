"""The Monte Carlo re-simulation and the LQR tracking (eqs. 6.27-6.29) against closed forms."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from gamespec.desensitize.montecarlo import monte_carlo
from gamespec.desensitize.spec import MonteCarloOptions
from gamespec.desensitize.tracking import CONTROL_WEIGHT, riccati_gains
from gamespec.ocp.symbolic import SymbolicOcp
from tests.desensitize.helpers import FINAL, TRAJECTORY, FileSolver, file_solver


@pytest.mark.parametrize(("a", "b"), [(-1.0, 1.0), (0.5, 2.0)])
def test_riccati_gains_are_the_scalar_closed_form(a: float, b: float) -> None:
    """For constant A = a, B = b the Riccati equation of eq. 6.27, -Ṗ = 2aP − b²P²/R, P(t_f) = 1,
    is a Bernoulli equation: z = 1/P obeys ż = 2a z − b²/R, so
    z(t) = e^{2a(t−t_f)} + b²/(2aR) (1 − e^{2a(t−t_f)}), and K = b P / R."""
    t = np.linspace(0.0, 3.0, 3001)
    A = np.full((t.size, 1, 1), a)
    B = np.full((t.size, 1, 1), b)
    K = riccati_gains(t, A, B)[:, 0, 0]
    e = np.exp(2 * a * (t - t[-1]))
    z = e + b * b / (2 * a * CONTROL_WEIGHT) * (1 - e)
    assert np.allclose(K, b / z / CONTROL_WEIGHT, rtol=1e-9)


def test_nominal_sample_reproduces_the_solution() -> None:
    """With a negligible spread every sample is the nominal: the re-simulated final state is the
    solution's, within the re-simulation's own accuracy (RK4 with about 500 steps along the mesh,
    under the control as the transcription holds it: ~1e-9 here, where a spline through the control
    points gave ~1e-4), and the tracking closed loop does not move it."""
    result = file_solver(
        FINAL,
        edit={"monte_carlo": {"samples": 20, "tracking": True}},
        uncertain={"rho": {"normal": {"std": 1e-12}}},
    ).solve()
    mc = result.metrics["monte_carlo"]
    for state in ("x1", "x2"):
        assert mc["final_state_mean"][state] == pytest.approx(result.states[state][-1], abs=1e-7)
        assert mc["tracking"]["final_state_mean"][state] == pytest.approx(
            mc["final_state_mean"][state], abs=1e-9
        )
    assert mc["cost_mean"] == pytest.approx(result.t_final)


def test_seed_makes_the_monte_carlo_reproducible() -> None:
    solver = file_solver(TRAJECTORY, edit={"monte_carlo": {"samples": 0}})
    result = solver.solve()
    ocp, uncertain = SymbolicOcp(solver.spec), solver.spec.problem.uncertain
    first, _ = monte_carlo(ocp, result, uncertain, MonteCarloOptions(samples=300, seed=7))
    again, _ = monte_carlo(ocp, result, uncertain, MonteCarloOptions(samples=300, seed=7))
    other, _ = monte_carlo(ocp, result, uncertain, MonteCarloOptions(samples=300, seed=8))
    assert first == again
    assert other["cost_mean"] != first["cost_mean"]


def test_path_constraint_violations_and_grid_inputs() -> None:
    """A grid input (a drift along the shore, tabulated on the control grid) is re-simulated with the
    control; a path constraint x1 ≤ 2.2, inactive on the nominal until near the end, is violated by
    some of the samples whose current carries them further: 0 < P < 1."""
    data = yaml.safe_load(TRAJECTORY.read_text())
    request = data.pop("transforms")[0]["desensitize"] | {"monte_carlo": {"samples": 400, "seed": 2}}
    data["problem"]["inputs"] = {"drift": {"default": "0.1*tau"}}
    data["problem"]["dynamics"]["x1"] = "cos(u) + rho*x2 + drift"
    data["problem"]["path_constraints"] = ["x1 <= 2.2"]
    result = FileSolver(data, request).solve()
    mc = result.metrics["monte_carlo"]
    assert result.ok
    assert mc["final_state_mean"]["x1"] == pytest.approx(result.states["x1"][-1], abs=5e-3)
    assert 0.0 < mc["violation_probability"] < 1.0
    assert result.states["x1"].max() <= 2.2 + 1e-6
