"""The linear-quadratic pursuit-evasion game of ``problems/ch7/lq_pursuit_evasion.yaml`` against its
closed-form open-loop saddle point.

Derivation. Players p (pursuer) and e (evader) in the plane, ``ṗ = u``, ``ė = v``, relative position
``δ = p − e`` (``δ̇ = u − v``), payoff ``J = s/2 |δ(T)|² + 1/2 ∫_0^T (r|u|² − q|v|²) dt`` minimized by
u, maximized by v. The Hamiltonian ``H = (r|u|² − q|v|²)/2 + λᵀ(u − v)`` gives ``u = −λ/r``,
``v = −λ/q`` and ``λ̇ = −∂H/∂δ = 0``, so ``λ = s δ(T)`` (the transversality condition) is constant
— the Riccati equation of this game, ``Ṗ = P (1/r − 1/q) P`` with ``P(T) = s``, read along the
open-loop path. Then ``δ(T) = δ(0) − T λ (1/r − 1/q)``, i.e.

    δ(T) = δ(0) / (1 + s T (1/r − 1/q)),   u = −s δ(T) / r,   v = −s δ(T) / q,

both constant, and ``J = s/2 |δ(T)|² + T/2 (r|u|² − q|v|²)``. The evader's problem is concave
(a saddle, not just a stationary point) when ``q > s T``: against any u, a constant v = c changes
the payoff by ``(s T² − q T)|c|²/2`` at second order.

Best responses: against a fixed evader whose displacement is ``V = ∫v``, the pursuer's best
response is constant, ``U = −s T (δ(0) − V) / (r + s T)``; against ``U = ∫u`` the evader's is
``V = −s T (δ(0) + U) / (q − s T)``. The Gauss–Seidel map contracts by
``ρ = s²T² / ((r + s T)(q − s T))`` per sweep and Jacobi by ``√ρ`` (1/6 and 0.41 for the file), so
both converge to the saddle point.

Because the controls are constant and the dynamics do not involve the state, Radau collocation of
degree 1 (backward Euler with piecewise-constant controls) is exact: the transcription adds no
error and the comparison is to the solver's tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest

from gamespec.loader import load, with_values
from gamespec.solving import compile_spec
from tests.conftest import PROBLEMS

FILE = PROBLEMS / "ch7" / "lq_pursuit_evasion.yaml"
SOLVER_TOL = 1e-6
"""IPOPT solves each response to tol 1e-8 on O(1) values; the iteration stops at a change of 1e-9."""


def closed_form(s: float, r: float, q: float, T: float, delta0: np.ndarray) -> dict[str, np.ndarray | float]:
    """The open-loop saddle point of the module docstring."""
    delta_T = delta0 / (1 + s * T * (1 / r - 1 / q))
    u, v = -s * delta_T / r, -s * delta_T / q
    payoff = s / 2 * delta_T @ delta_T + T / 2 * (r * u @ u - q * v @ v)
    return {"delta_T": delta_T, "u": u, "v": v, "payoff": float(payoff)}


def expected(spec) -> dict:
    p = spec.problem.parameters
    x0 = {n: st.initial for n, st in spec.problem.states.items()}
    delta0 = np.array([x0["xp"] - x0["xe"], x0["yp"] - x0["ye"]])
    return closed_form(p["s"], p["r"], p["q"], p["T"], delta0) | {"x0": x0}


@pytest.mark.parametrize(
    ("scheme", "backend"), [("gauss_seidel", "casadi"), ("jacobi", "casadi"), ("gauss_seidel", "pyomo")]
)
def test_iteration_converges_to_the_closed_form_saddle(scheme, backend):
    spec = load(FILE, [f"game.scheme={scheme}", f"game.backend={backend}"])
    result = compile_spec(spec).solve()
    want = expected(spec)
    run = result.metrics["best_response"]["pursuer"]
    assert result.ok and run["converged"], result.message
    t = result.time
    for name, ctrl, start in (("xp", "u1", "xp"), ("yp", "u2", "yp")):
        k = 0 if name == "xp" else 1
        np.testing.assert_allclose(result.controls[ctrl], want["u"][k], atol=SOLVER_TOL)
        np.testing.assert_allclose(result.states[name], want["x0"][start] + want["u"][k] * t, atol=SOLVER_TOL)
    for name, ctrl in (("xe", "v1"), ("ye", "v2")):
        k = 0 if name == "xe" else 1
        np.testing.assert_allclose(result.controls[ctrl], want["v"][k], atol=SOLVER_TOL)
        np.testing.assert_allclose(result.states[name], want["x0"][name] + want["v"][k] * t, atol=SOLVER_TOL)
    assert result.objective == pytest.approx(want["payoff"], abs=SOLVER_TOL)


def test_contraction_rate_of_the_iteration():
    """Gauss–Seidel changes shrink by ρ = s²T²/((r + sT)(q − sT)) per sweep (module docstring)."""
    spec = load(FILE)
    result = compile_spec(spec).solve()
    changes = [it["changes"]["evader"] for it in result.metrics["best_response"]["pursuer"]["history"]]
    p = spec.problem.parameters
    rate = (p["s"] * p["T"]) ** 2 / ((p["r"] + p["s"] * p["T"]) * (p["q"] - p["s"] * p["T"]))
    ratios = np.array(changes[2:6]) / np.array(changes[1:5])
    np.testing.assert_allclose(ratios, rate, rtol=1e-3)


def test_reloaded_parameters_resolve_the_compiled_game():
    """A new value of a runtime parameter re-solves the compiled players (no new build) and gives
    the closed form for that value."""
    spec = load(FILE)
    solver = compile_spec(spec)
    solver.solve()
    builds = solver.compiled.model.builds
    result = solver.solve(parameters={"q": 6.0})
    want = expected(with_values(spec, {"q": 6.0}))
    assert solver.compiled.model.builds == builds
    np.testing.assert_allclose(result.controls["v1"], want["v"][0], atol=SOLVER_TOL)
    assert result.objective == pytest.approx(want["payoff"], abs=SOLVER_TOL)


def test_summary_leads_with_the_equilibrium_and_the_game_value(cli):
    """``gamespec solve`` says how the iteration ended and the value, read from the Result."""
    from gamespec.summaries import outcome

    result = compile_spec(load(FILE)).solve()
    rows = dict(outcome(result))
    run = result.metrics["best_response"]["pursuer"]
    assert rows["equilibrium"] == f"{run['outcome']} after {run['iterations']} Gauss–Seidel iterations"
    assert rows["game value"] == result.objective
    code, out, _ = cli("solve", str(FILE))
    assert code == 0 and "Gauss–Seidel iterations" in out and "game value" in out
