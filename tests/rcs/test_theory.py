"""RCS against theory: S_g against finite differences of g along re-simulations (eq. 6.31), the
trade-off on the single-obstacle file, and the collision probability against a closed form."""

from itertools import pairwise

import numpy as np
import pytest
import yaml
from scipy.stats import norm

from gamespec.desensitize.simulate import rk4
from gamespec.loader import load, spec_from_dict
from gamespec.ocp.control_signal import transcribed_signal
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.rcs.sensitivity import inequalities
from gamespec.solving import compile_spec, solve
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.language import TIME, symbol
from tests.conftest import PROBLEMS

SINGLE = PROBLEMS / "ch6" / "rcs_single_obstacle.yaml"


def drifting_agent() -> dict:
    """An agent in a current ρ·x along y (so its states depend on ρ) past a static obstacle."""
    return {
        "kind": "optimal_control",
        "name": "drift",
        "problem": {
            "parameters": {"rho": 0.2, "Q": 0.5},
            "uncertain": {"rho": {"normal": {"std": 0.05}}},
            "states": {"x": {"initial": 0.0, "final": 6.0}, "y": {"initial": 0.0}},
            "controls": {"u": {"lower": "-pi", "upper": "pi"}},
            "dynamics": {"x": "cos(u)", "y": "sin(u) + rho*x"},
            "objective": {"mayer": "t_f"},
            "time": {"final": "free", "bounds": [6.0, 20.0], "guess": 7.0},
        },
        "transforms": [
            {"moving_obstacles": {"obstacles": {"rock": {"center": [3.0, 1.5], "radius": 1.0}}}},
            {"rcs": {"weight": "Q", "monte_carlo": {"samples": 0}}},
        ],
        "method": {"scheme": "radau", "intervals": 40, "degree": 3},
        "guess": {"states": {"x": "6*tau", "y": "-sin(pi*tau)"}},
    }


def test_constraint_sensitivity_matches_finite_differences():
    solver = compile_spec(spec_from_dict(drifting_agent()))
    result = solver.solve()
    assert result.ok
    assert "S_y_rho" in result.states and "S_x_rho" not in result.states  # S_x ≡ 0 is left out
    spec = solver.steps[0].target  # after moving_obstacles: the constraint, no sensitivity states
    ocp = SymbolicOcp(spec)
    g = inequalities(ocp)[0].g
    G = numeric_function([g], [*ocp.p, *ocp.x, TIME])
    t = np.asarray(result.time)
    h, rho = 1e-4, result.parameters["rho"]
    x0 = np.array([[0.0], [0.0]])
    steps = 4000
    values = []
    for r in (rho + h, rho - h):
        params = {symbol(k): v for k, v in result.parameters.items()} | {symbol("rho"): r}
        run = rk4(
            ocp, x0, transcribed_signal(result, ocp.controls), params, t[0], float(result.t_final), steps
        )
        xs = [np.interp(t, run.t, run.x[:, i, 0]) for i in range(2)]
        args = [params[p] for p in ocp.p]
        values.append(np.broadcast_to(G(*args, *xs, t), (1, t.size))[0])
    fd = (values[0] - values[1]) / (2 * h)
    S_g = result.arrays["S_g0_rho"]
    scale = np.abs(S_g).max()
    assert scale > 0.1
    np.testing.assert_allclose(S_g, fd, atol=2e-3 * scale)


def test_time_rises_and_collisions_fall_with_the_weight():
    solver = compile_spec(SINGLE, options={"warm_start": False})
    rows = []
    for q in (0.0, 0.3, 1.0, 5.0):
        r = solver.solve(parameters={"problem.parameters.Q": q})
        assert r.ok, r.message
        mc = r.metrics["monte_carlo"]
        rows.append((r.t_final, mc["collision_probability"], mc["collision_probability_ci"]))
    times = [row[0] for row in rows]
    assert all(b > a for a, b in pairwise(times))
    for (_, p, _), (_, q, ci) in pairwise(rows):
        assert q <= p + (ci[1] - ci[0])  # non-increasing up to sampling error (same seed)
    assert rows[-1][2][1] < rows[0][2][0]  # the heaviest weight is safer beyond both intervals


def straight_past_one_obstacle(samples: int, std: float) -> dict:
    """Agent at v along the x-axis for 12 s (y held at 0); obstacle on x = c from (c, -d) up at ρ,
    passing ahead of the nominal agent (ρ̂ = 0.75, closest distance 1.4)."""
    return {
        "kind": "optimal_control",
        "name": "straight",
        "problem": {
            "parameters": {"rho": 0.75, "v": 1.0, "c": 5.0, "d": 2.0, "r_o": 1.0, "k": 0.0},
            "uncertain": {"rho": {"normal": {"std": std}}},
            "states": {"x": {"initial": 0.0}, "y": {"initial": 0.0}},
            "controls": {"u": {"lower": -1.0, "upper": 1.0}},
            "dynamics": {"x": "v", "y": "k*u"},
            "objective": {"lagrange": "u**2"},
            "time": {"final": 12.0},
        },
        "transforms": [
            {
                "moving_obstacles": {
                    "obstacles": {"o": {"center": ["c", "-d"], "velocity": [0, "rho"], "radius": "r_o"}}
                }
            },
            {"rcs": {"weight": 0.0, "monte_carlo": {"samples": samples, "seed": 3, "steps": 3000}}},
        ],
        "method": {"scheme": "radau", "intervals": 10, "degree": 3},
    }


def test_collision_probability_matches_the_normal_cdf():
    """Relative motion p0 + t·w, p0 = (-c, d), w = (v, -ρ): the closest distance |cρ - dv|/|w| is
    below r_o for ρ between v(cd ∓ r_o√(c² + d² - r_o²))/(c² - r_o²)."""
    n, std = 4000, 0.2
    result = solve(spec_from_dict(straight_past_one_obstacle(n, std)))
    assert result.ok
    c, d, r, v, mu = 5.0, 2.0, 1.0, 1.0, 0.75
    root = r * np.sqrt(c**2 + d**2 - r**2)
    low, high = v * (c * d - root) / (c**2 - r**2), v * (c * d + root) / (c**2 - r**2)
    exact = norm.cdf(high, mu, std) - norm.cdf(low, mu, std)
    p = result.metrics["monte_carlo"]["collision_probability"]
    assert abs(p - exact) < 4 * np.sqrt(exact * (1 - exact) / n)
    ci = result.metrics["monte_carlo"]["collision_probability_ci"]
    assert ci[0] < p < ci[1]
    assert collision_probability_along(result, std) == pytest.approx(exact, abs=1e-3)


def collision_probability_along(result, std: float) -> float:
    """P(min_t D(t; ρ) < r_o) for ρ ~ N(ρ̂, std²), by quadrature over ρ along the returned path (the
    agent's dynamics do not hold ρ, so its path is the same for every ρ), D the distance to the
    obstacle at (c, ρt - d) of the ch6 RCS files."""
    p = result.parameters
    t = np.linspace(result.time[0], result.time[-1], 2000)
    x, y = (np.interp(t, result.time, result.states[name]) for name in ("x", "y"))
    edges = np.linspace(p["rho"] - 8 * std, p["rho"] + 8 * std, 16001)
    rho = 0.5 * (edges[1:] + edges[:-1])
    closest = np.concatenate(
        [np.hypot(x - p["c"], y - (r[:, None] * t - p["d"])).min(axis=1) for r in np.split(rho, 32)]
    )
    return float(np.diff(norm.cdf(edges, p["rho"], std))[closest < p["r_o"]].sum())


@pytest.mark.parametrize("name", ["rcs_single_obstacle", "rcs_constraint_form"])  # car_vs_train: its own file
def test_files_solve(name):
    """The file solves, and its Monte Carlo collision probability is the quadrature's along the
    returned path within four binomial standard deviations (and one sample)."""
    path = PROBLEMS / "ch6" / f"{name}.yaml"
    data = yaml.safe_load(path.read_text())
    assert data["transforms"][0]["moving_obstacles"]["obstacles"]["obstacle"] == {
        "center": ["c", "-d"],
        "velocity": [0, "rho"],
        "radius": "r_o",
    }
    result = solve(path)
    assert result.ok, result.message
    carlo = result.metrics["monte_carlo"]
    exact = collision_probability_along(result, data["problem"]["uncertain"]["rho"]["normal"]["std"])
    n = carlo["samples"]
    assert abs(carlo["collision_probability"] - exact) <= 4 * np.sqrt(exact * (1 - exact) / n) + 1 / n


def test_constraint_form_power_is_a_parameter():
    """One compiled model re-solved for three powers, each answer holding the constraint of its own
    β: the obstacle at (c, ρt - d) does not move the agent, so S_g = ∂g_β/∂ρ of eq. 6.41 is
    β D^(β-2) (y - ρt + d) t along the returned path (D the distance to the obstacle), which a β
    left at the file's value fails. Each solve starts cold: warm from the beta = 1 optimum,
    beta = 4 is a hard continuation for IPOPT (756 iterations to another local optimum on the flat
    SX graph, a failed restoration on the assembled one), where a cold start takes 42 iterations to
    the same optimum on every graph."""
    spec = load(PROBLEMS / "ch6" / "rcs_constraint_form.yaml", ["solver.options.casadi.warm_start=false"])
    solver = compile_spec(spec)
    for beta in (0.5, 1.0, 4.0):
        result = solver.solve(parameters={"problem.parameters.beta": beta})
        assert result.ok, result.message
        assert result.metrics["obstacle_power"] == beta
        p = result.parameters
        t = np.asarray(result.time)
        dx = result.states["x"] - p["c"]
        dy = result.states["y"] - (p["rho"] * t - p["d"])
        distance = np.hypot(dx, dy)
        assert distance.min() >= p["r_o"] * (1 - 1e-6)
        expected = beta * distance ** (beta - 2) * dy * t
        np.testing.assert_allclose(result.arrays["S_g0_rho"], expected, atol=1e-8 * np.abs(expected).max())


def test_plain_constraint_sensitivity_option():
    data = yaml.safe_load(SINGLE.read_text())
    data["transforms"][1]["rcs"] |= {"relevant": False, "monte_carlo": {"samples": 0}}
    result = solve(spec_from_dict(data))
    assert result.ok
    # the cost is the collocated state's, the measure a dense trapezoid along the solution: they
    # agree to the 40-interval mesh's accuracy
    np.testing.assert_allclose(
        result.metrics["sensitivity_cost"],
        result.metrics["sensitivity_measure"] * data["problem"]["parameters"]["Q"],
        rtol=1e-3,
    )


def test_a_failed_check_restarts_from_the_other_homotopy_class():
    """At Q = 20 the solve ahead of the obstacle fails the defect check of the RCS cost state; the
    file's restart (behind it) passes every check at a lower cost, and is what the solve returns."""
    data = yaml.safe_load(SINGLE.read_text())
    data["problem"]["parameters"]["Q"] = 20.0
    rcs = data["transforms"][1]["rcs"]
    rcs["monte_carlo"] = {"samples": 0}
    restarts = rcs.pop("restarts")
    ahead = solve(spec_from_dict(data))
    assert not ahead.metrics["checks_passed"]["max_defect_relative"]
    rcs["restarts"] = restarts
    best = solve(spec_from_dict(data))
    assert best.status.value == "optimal" and "starting point 1 of 1" in best.message
    assert all(best.metrics["checks_passed"].values())
    behind = solve(spec_from_dict(data | {"guess": restarts[0]}))
    assert best.objective == pytest.approx(behind.objective, rel=1e-6)
    assert best.objective < ahead.objective
