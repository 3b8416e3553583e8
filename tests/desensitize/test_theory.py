"""Desensitized optimal control checked against theory (issue 10, "Checked by").

Re-simulations run the file's dynamics by RK4 on a fine grid under the Result's control. That
control is known at the collocation points only, so a re-simulation differs from the collocation
solution by the representation error of the control; each test measures that error on the nominal
states (``nominal_gap``) and allows a multiple of it, relative to the size of what it compares.
"""

from __future__ import annotations

import numpy as np
import pytest

from gamespec.desensitize.simulate import cost
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.symbolic.language import symbol
from tests.desensitize.helpers import (
    FINAL,
    LQR_FILES,
    SEYWALD,
    TRAJECTORY,
    FileSolver,
    file_solver,
    resimulate,
)

NO_MC = {"monte_carlo": {"samples": 0}}
GAP_FACTOR = 10.0
"""How many times the nominal re-simulation gap a derived quantity may differ by."""


def at_nodes(run, result, index: int, column: int) -> np.ndarray:
    """A re-simulated state on the Result's grid (the RK4 grid is fine enough for linear interpolation)."""
    return np.interp(result.time, run.t, run.x[:, index, column])


def nominal_gap(spec, result) -> float:
    """Largest relative difference between the re-simulated nominal states and the solution's."""
    run = resimulate(spec, result, {})
    ocp = SymbolicOcp(spec)
    gaps = [
        np.abs(at_nodes(run, result, i, 0) - result.states[s]).max()
        / max(np.abs(result.states[s]).max(), 1.0)
        for i, s in enumerate(ocp.states)
    ]
    return max(gaps)


@pytest.mark.parametrize("path", [TRAJECTORY, FINAL])
def test_sensitivity_states_are_finite_differences_of_resimulations(path) -> None:
    """S from the augmented solve (eq. 6.12) equals (x(ρ+δ) − x(ρ−δ)) / 2δ along the whole path."""
    solver = file_solver(path, edit=NO_MC)
    result = solver.solve()
    rho, delta = result.parameters["rho"], 1e-4
    run = resimulate(solver.spec, result, {"rho": np.array([rho + delta, rho - delta])})
    gap = nominal_gap(solver.spec, result)
    for i, state in enumerate(SymbolicOcp(solver.spec).states):
        fd = (at_nodes(run, result, i, 0) - at_nodes(run, result, i, 1)) / (2 * delta)
        S = result.states[f"S_{state}_rho"]
        scale = max(np.abs(S).max(), 1e-3)
        assert np.abs(fd - S).max() <= GAP_FACTOR * gap * scale + 1e-6


def test_initial_state_depending_on_the_parameter_starts_the_sensitivity_there(tmp_path) -> None:
    """With x1(t0) = 0.05 ρ, S(t0) = ∂x0/∂ρ = 0.05, and S still matches finite differences."""
    solver = file_solver(TRAJECTORY, edit={**NO_MC, "trajectory": {"S_x1_rho": 1.0}})
    data = solver.spec.model_dump()
    data["problem"]["states"]["x1"]["initial"] = "0.05*rho"
    solver = FileSolver(data, solver.request)
    result = solver.solve()
    assert result.states["S_x1_rho"][0] == pytest.approx(0.05)
    rho, delta = result.parameters["rho"], 1e-4
    x0 = np.array([[0.05 * (rho + delta), 0.05 * (rho - delta)], [0.0, 0.0]])
    run = resimulate(solver.spec, result, {"rho": np.array([rho + delta, rho - delta])}, x0=x0)
    fd = (run.final[0, 0] - run.final[0, 1]) / (2 * delta)
    gap = nominal_gap(solver.spec, result)
    assert fd == pytest.approx(result.states["S_x1_rho"][-1], abs=GAP_FACTOR * gap + 1e-6)


@pytest.mark.parametrize("spread", [{"uniform": {"percent": 1}}, {"normal": {"std": 0.05}}])
def test_monte_carlo_spread_is_the_propagated_one(spread) -> None:
    """For small spreads std(x1(t_f)) ≈ |S1(t_f)| · std(ρ) (eq. 6.15), within the sampling error of
    a standard deviation (≈ 0.45/√N for uniform, 0.71/√N for normal draws; five of them allowed) and
    the second-order term (the spread itself, relative)."""
    n = 4000
    solver = file_solver(FINAL, edit={"monte_carlo": {"samples": n, "seed": 3}}, uncertain={"rho": spread})
    result = solver.solve()
    rho = result.parameters["rho"]
    sigma = solver.spec.problem.uncertain["rho"].std(rho)
    predicted = abs(result.states["S_x1_rho"][-1]) * sigma
    mc = result.metrics["monte_carlo"]
    assert mc["samples"] == n
    tol = 5 * 0.71 / np.sqrt(n) + sigma / rho
    assert mc["final_state_std"]["x1"] == pytest.approx(predicted, rel=tol)
    assert mc["final_state_std"]["x2"] == pytest.approx(0.0, abs=1e-9)  # S2 ≡ 0 (eq. 6.24)


def test_seywald_and_sensitivity_functions_agree_on_the_final_sensitivity() -> None:
    """Under the control of the Seywald solve, ∂x1(t_f)/∂ρ from the transition matrix at t0
    (Φ_{x1,ρ}(t_f, t0), eq. 6.6) equals S1(t_f) of the sensitivity equations (eq. 6.12) re-simulated."""
    seywald = file_solver(SEYWALD, edit=NO_MC)
    result = seywald.solve()
    sensitivity = FileSolver(seywald.spec.model_dump(), {**seywald.request, "method": "sensitivity"})
    augmented = SymbolicOcp(sensitivity.target)
    x0 = np.zeros((len(augmented.states), 1))
    run = resimulate(sensitivity.target, result, {}, x0=x0)
    s1 = run.final[augmented.states.index("S_x1_rho"), 0]
    gap = nominal_gap(seywald.spec, result)
    assert result.states["Phi_x1_P_rho"][0] == pytest.approx(s1, abs=GAP_FACTOR * gap * abs(s1) + 1e-6)
    counts = result.metrics["desensitization"]
    n, ell = 2, 1
    assert counts["augmented_states"] == counts["formula_states"] == (n + ell) ** 2 + n + ell
    assert sensitivity.target.problem.states.keys() >= {"S_x1_rho", "S_x2_rho"}
    assert len(sensitivity.target.problem.states) == n + n * ell


def test_costate_and_seywald_coincide_when_the_cost_is_a_final_state() -> None:
    """For J = -x1(t_f), Theorem 7 gives μ(t) = ∂x1(t_f)/∂ρ from t on = Φ_{x1,ρ}(t_f, t), so C-DOC
    (eq. 6.62) and Seywald's eq. 6.7 pose the same problem and find the same solution."""
    costate = file_solver(TRAJECTORY, edit={**NO_MC, "method": "costate", "trajectory": "alpha"}).solve()
    seywald = file_solver(TRAJECTORY, edit={**NO_MC, "method": "seywald"}).solve()
    assert costate.objective == pytest.approx(seywald.objective, rel=1e-6)
    assert np.allclose(costate.states["mu_rho"], seywald.states["Phi_x1_P_rho"], atol=1e-5)


def riccati_cost(a: float, b: float, r1: float, r2: float, tf: float, x0: float) -> float:
    """Closed-form LQR cost ½ P(0) x0² of J = ∫ ½(R1 x² + R2 u²) (eq. 6.65; R1 on the state): with
    k = b²/R2 the Riccati equation -Ṗ = 2aP + R1 - kP², P(t_f) = 0, has the roots
    P± = (a ± s)/k, s = √(a² + k R1), and P = (P+ − r P−)/(1 − r), r = (P+/P−) e^{−2s(t_f − t)}."""
    k = b * b / r2
    s = np.sqrt(a * a + k * r1)
    p_plus, p_minus = (a + s) / k, (a - s) / k
    r = p_plus / p_minus * np.exp(-2 * s * tf)
    return 0.5 * (p_plus - r * p_minus) / (1 - r) * x0 * x0


@pytest.mark.parametrize("path", LQR_FILES, ids=lambda p: p.stem)
def test_cdoc_without_weight_is_the_riccati_lqr(path) -> None:
    """C-DOC with Q = 0 solves the plain LQR: its cost converges to ½ P(0) x0² as the mesh is refined
    (Radau collocation of degree 3: order 2d − 1 = 5 in the cost, so doubling the intervals divides
    the error by far more than 8), and the co-state dynamics only add states."""
    errors = []
    for intervals in (40, 80):
        unrefined = {"intervals": intervals, "refine": None}  # the files refine: here the order is studied
        result = file_solver(path, edit=NO_MC, method=unrefined).solve({"Q": 0.0})
        p = result.parameters
        expected = riccati_cost(p["a"], p["b"], p["R1"], p["R2"], float(result.t_final), 1.0)
        errors.append(abs(result.objective - expected) / expected)
        assert result.metrics["nominal_objective"] == pytest.approx(result.objective, rel=1e-12)
        assert result.metrics["sensitivity_cost"] == pytest.approx(0.0, abs=1e-12)
    assert errors[0] < 1e-3
    assert errors[1] < errors[0] / 8 or errors[1] < 1e-9


@pytest.mark.parametrize("path", [LQR_FILES[1], TRAJECTORY], ids=lambda p: p.stem)
def test_theorem_7_costates_are_gradients_of_the_cost_to_go(path) -> None:
    """For the solution's (fixed) control, λ(t) = ∂C/∂x (eq. 6.55) and μ(t) = ∂C/∂ρ (eq. 6.61b),
    with C the cost-to-go (eq. 6.54) from the state at t, by central differences of re-simulations."""
    solver = file_solver(  # on the file's 40 intervals, unrefined: as the theorem was checked before
        path,
        edit={**NO_MC, "method": "costate", "trajectory": "alpha"} if path == TRAJECTORY else NO_MC,
        method={"refine": None},
    )
    result = solver.solve()
    _check_theorem_7(solver.spec, result)


def test_theorem_7_on_nonlinear_dynamics_with_a_nonlinear_mayer_term(tmp_path) -> None:
    """A damped pendulum with two uncertain parameters and φ = q(t_f)² + w(t_f)²: λ(t_f) = 2x(t_f)
    becomes a boundary constraint, and λ, μ are still the cost-to-go gradients (Theorem 7)."""
    spec = {
        "kind": "optimal_control",
        "name": "pendulum",
        "problem": {
            "parameters": {"g": 2.0, "c": 0.3, "Q": 1.0},
            "uncertain": {"g": {"normal": {"std": 0.1}}, "c": {"uniform": {"percent": 10}}},
            "states": {"q": {"initial": 1.0}, "w": {"initial": 0.0}},
            "controls": {"u": {"lower": -2, "upper": 2}},
            "dynamics": {"q": "w", "w": "-g*sin(q) - c*w + u"},
            "objective": {"mayer": "w_f**2 + q_f**2", "lagrange": "0.5*q**2 + 0.1*u**2"},
            "time": {"final": 3.0},
        },
        "method": {"intervals": 30, "degree": 3},
    }
    solver = FileSolver(spec, {"method": "costate", "trajectory": "Q", **NO_MC})
    assert len(solver.target.problem.boundary_constraints) == 2
    result = solver.solve()
    assert result.ok
    _check_theorem_7(solver.spec, result)


def _check_theorem_7(spec, result) -> None:
    """Per checked time, one re-simulation of 2(n + ℓ) samples: ±δ on each state, then on each
    uncertain parameter."""
    ocp = SymbolicOcp(spec)
    delta = 1e-5
    gap = nominal_gap(spec, result)
    names = [f"lambda_{s}" for s in ocp.states] + [f"mu_{p}" for p in spec.problem.uncertain]
    n, width = len(ocp.states), 2 * len(names)
    signs = np.tile([delta, -delta], len(names))
    params = {k: np.full(width, v) for k, v in result.parameters.items()}
    for j, name in enumerate(spec.problem.uncertain):
        params[name][2 * (n + j) : 2 * (n + j) + 2] += signs[:2]
    values = {symbol(k): v for k, v in params.items()}
    nodes = len(result.time)
    for k in (0, nodes // 4, nodes // 2, 3 * nodes // 4):
        tk = float(result.time[k])
        x0 = np.tile(np.array([[result.states[s][k]] for s in ocp.states]), (1, width))
        for i in range(n):
            x0[i, 2 * i : 2 * i + 2] += signs[:2]
        c = cost(ocp, x0, resimulate(spec, result, params, t0=tk, x0=x0, steps=1000), values)
        gradients = (c[0::2] - c[1::2]) / (2 * delta)
        scale = max(np.abs(gradients).max(), 1e-3)
        for name, fd in zip(names, gradients, strict=True):
            assert result.states[name][k] == pytest.approx(fd, abs=GAP_FACTOR * gap * scale + 1e-6), (
                tk,
                name,
            )


def test_trends_in_alpha_are_monotone() -> None:
    """Raising α trades the original cost for sensitivity (Figs. 6.1, 6.3): x1(t_f) falls and ∫S1²
    falls on the maximum-range boat; t_f rises and |S1(t_f)| falls on the minimum-time boat; the
    Monte Carlo dispersion of x1(t_f) falls with it. One compiled model re-solves every α."""
    trajectory = file_solver(TRAJECTORY, edit={"monte_carlo": {"samples": 500}})
    runs = [trajectory.solve({"alpha": a}) for a in (0.0, 75.0, 500.0)]
    x1f = [r.metrics["nominal_objective"] for r in runs]
    spread = [r.metrics["monte_carlo"]["final_state_std"]["x1"] for r in runs]
    measure = [np.trapezoid(r.states["S_x1_rho"] ** 2, r.time) for r in runs]
    assert x1f[0] > x1f[1] > x1f[2]
    assert measure[0] > measure[1] > measure[2]
    assert spread[0] > spread[1] > spread[2]
    final = file_solver(FINAL, edit={"monte_carlo": {"samples": 500}})
    runs = [final.solve({"alpha": a}) for a in (0.0, 25.0, 1000.0)]
    tf = [r.t_final for r in runs]
    s1 = [abs(r.states["S_x1_rho"][-1]) for r in runs]
    assert tf[0] < tf[1] < tf[2]
    assert s1[0] > s1[1] > s1[2]
