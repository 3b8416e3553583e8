"""car_vs_train (§6.4.3) against an independent reduction of the problem.

Beyond the track (``φ(x) ≈ 0`` for ``|x - c| > 1.2 w_o``) the RCS integrand vanishes, so there
the minimum-time Hamiltonian ``H = 1·0 + λ u`` is minimized by ``u = v_max`` (λ < 0: a later
arrival costs time); before the track the car only has to wait (any profile reaching the edge at
the same time costs the same). So the optimum is *wait near the track, then full speed*: a problem
in one unknown, the time ``t_s`` the car leaves ``x_s`` (off the track) at full speed, with
``J(t_s) = t_s + (10 - x_s)/v_max + Q ∫ S_r² dt`` integrated by SciPy's adaptive quadrature along
that motion (eqs. 6.35, 6.43-6.45 written out here, not taken from the transform).
"""

import numpy as np
import pytest
import yaml
from scipy.integrate import quad
from scipy.optimize import minimize_scalar

from gamespec.loader import load, spec_from_dict
from gamespec.solving import solve
from tests.conftest import PROBLEMS

FILE = PROBLEMS / "ch6" / "car_vs_train.yaml"


def risk_rate(x, t, p: dict[str, float], gamma: int):
    """``S_r²`` for the car at ``x`` at time ``t``: ``S_r = r(g) ∂g/∂ρ`` with
    ``g = φ(x)(r_o² - z²)``, ``z = -d + ρt`` (eqs. 6.43-6.45) and r of eq. 6.35 at min(g, 0)."""
    phi = np.exp(-(((x - p["c"]) / p["w_o"]) ** gamma))
    z = -p["d"] + p["rho"] * t
    g = phi * (p["r_o"] ** 2 - z**2)
    e = np.exp(np.minimum(g, 0.0))
    return (e / (1 + e) ** 2 * phi * (-2 * z * t)) ** 2


def reduced_cost(t_s: float, p: dict[str, float], gamma: int, x_s: float) -> float:
    """``J(t_s)`` of the module doc (the car at rest at ``x_s`` until ``t_s``, then at v_max)."""
    v = p["v_max"]

    def risk(t: float) -> float:
        return float(risk_rate(x_s + v * (t - t_s), t, p, gamma))

    edges = [t_s + (p["c"] - p["w_o"] - x_s) / v, t_s + (p["c"] + p["w_o"] - x_s) / v]
    end = t_s + (p["c"] + 2 * p["w_o"] - x_s) / v
    integral = quad(risk, t_s, end, points=edges, limit=400)[0]
    return t_s + (10.0 - x_s) / v + p["Q"] * integral


def reduced_optimum(p: dict[str, float], gamma: int) -> tuple[float, float]:
    """The minimum of ``J`` over ``t_s`` after the train has passed (``t_s`` such that the car
    reaches the track no earlier than ``(d + r_o)/ρ``) and the final time there."""
    x_s = p["c"] - 2 * p["w_o"]
    first = (p["d"] + p["r_o"]) / p["rho"] - (p["w_o"]) / p["v_max"]
    grid = np.arange(first, first + 25.0, 0.25)
    values = [reduced_cost(t, p, gamma, x_s) for t in grid]
    i = int(np.argmin(values))
    best = minimize_scalar(
        reduced_cost,
        bounds=(grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]),
        args=(p, gamma, x_s),
        method="bounded",
        options={"xatol": 1e-5},
    )
    return float(best.fun), float(best.x + (10.0 - x_s) / p["v_max"])


@pytest.mark.slow
def test_q10_is_the_wait_then_full_speed_optimum():
    """The file's solve at Q = 10 against the reduction (its Monte Carlo of 1000 samples left out:
    nothing here reads it)."""
    no_monte_carlo = load(FILE, ["transforms.1.rcs.monte_carlo.samples=0"])
    result = solve(no_monte_carlo, parameters={"problem.parameters.Q": 10.0})
    assert result.status.value == "optimal", result.message
    assert all(result.metrics["checks_passed"].values()), result.checks
    assert result.t_final <= 26.0
    spec = load(FILE, ["problem.parameters.Q=10"])
    p = {k: float(v) for k, v in spec.problem.parameters.items()}
    gamma = spec.transforms[0]["moving_obstacles"]["obstacles"]["train"]["track"]["gamma"]
    J, t_final = reduced_optimum(p, gamma)
    assert result.objective == pytest.approx(J, abs=0.02)
    assert result.t_final == pytest.approx(t_final, abs=0.05)
    # the risk cost the solver integrated (a state, refined to its tolerance) is the true one, and
    # the dense trapezoid of the unit-weight integrand along the solution agrees with it
    assert result.metrics["sensitivity_cost"] == pytest.approx(J - t_final, abs=0.03)
    assert p["Q"] * result.metrics["sensitivity_measure"] == pytest.approx(
        result.metrics["sensitivity_cost"], rel=1e-3
    )
    x = np.interp(result.control_time, result.time, result.states["x"])
    beyond = x > p["c"] + 1.2 * p["w_o"]
    u = np.asarray(result.controls["u"])
    assert beyond.any() and np.all(u[beyond] >= p["v_max"] - 1e-3)


@pytest.mark.slow
def test_q0_enters_the_track_as_the_train_leaves_it():
    """Q = 0: minimum time under the crossing constraint alone; the track is free once the train's
    safe circle has left the car's line, at t = (d + r_o)/ρ, and the car then crosses from the track's
    edge at full speed: t_f = (d + r_o)/ρ + (10 - (c - w_o))/v_max, up to how close to the edge the
    super-Gaussian lets it wait (γ = 20: 0.07 closer) and where the shipped mesh's collocation points
    fall in the edge (the constraint holds at them: 0.2 s later on 100 intervals, 0.06 s on 300)."""
    result = solve(FILE, parameters={"problem.parameters.Q": 0.0})
    assert result.status.value == "optimal", result.message
    assert all(result.metrics["checks_passed"].values()), result.checks
    p = {k: float(v) for k, v in load(FILE).problem.parameters.items()}
    leaves = (p["d"] + p["r_o"]) / p["rho"]
    assert result.t_final == pytest.approx(leaves + (10.0 - (p["c"] - p["w_o"])) / p["v_max"], abs=0.25)


def test_the_cost_state_exposes_an_under_resolved_risk():
    """The setup of earlier versions (60 intervals, no refinement, a linear guess): the collocation
    points step over the track's edges, so the risk the NLP sees is a fraction of the true one. As
    a Lagrange term nothing says so (the dynamics x' = u are integrated exactly); as a state, its
    re-integration between the points fails the defect check and the transform restarts."""
    data = yaml.safe_load(FILE.read_text())
    data["problem"]["parameters"]["Q"] = 10.0
    data["method"] = {"scheme": "radau", "intervals": 60, "degree": 3}
    data["guess"] = {"states": {"x": "10*tau"}, "controls": {"u": 0.33}}
    rcs = data["transforms"][1]["rcs"]
    rcs |= {"monte_carlo": {"samples": 0}, "restarts": []}
    hidden = solve(
        spec_from_dict({**data, "transforms": [data["transforms"][0], {"rcs": rcs | {"cost_state": False}}]})
    )
    assert hidden.metrics["checks_passed"]["max_defect_relative"]
    seen = solve(spec_from_dict(data))
    assert not seen.metrics["checks_passed"]["max_defect_relative"]
    assert seen.status.value != "optimal" and "max_defect_relative" in seen.message
    # along the Lagrange-form solution (x linear between its points, 200 steps each) the risk is
    # several times what the NLP integrated
    p = data["problem"]["parameters"]
    t = np.linspace(0.0, hidden.t_final, 200 * len(hidden.time))
    x = np.interp(t, hidden.time, hidden.states["x"])
    gamma = data["transforms"][0]["moving_obstacles"]["obstacles"]["train"]["track"]["gamma"]
    true_risk = p["Q"] * np.trapezoid(risk_rate(x, t, p, gamma), t)
    assert true_risk > 3 * hidden.metrics["sensitivity_cost"]
