"""The CasADi collocation backend checked against theory: closed forms, convergence order,
costates, simultaneous capture and a zero Hamiltonian (issue 2, "Checked by")."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

import gamespec
from tests.conftest import PROBLEMS

ONE_ON_ONE = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"
TWO_ON_ONE = PROBLEMS / "ch2" / "pure_pursuit_two_on_one.yaml"
ZERMELO_RANGE = PROBLEMS / "ch6" / "zermelo_max_range.yaml"
ZERMELO_TIME = PROBLEMS / "ch6" / "zermelo_min_time.yaml"


def test_one_on_one_capture_time_is_the_closed_form() -> None:
    """Pure evasion along the line of sight: t_c = (r0 - eps) / (u - v)."""
    solver = gamespec.compile_spec(ONE_ON_ONE)
    for v in (0.5, 0.3, 0.8):
        result = solver.solve(parameters={"v": v})
        p = result.parameters
        assert result.status == gamespec.Status.OPTIMAL
        assert result.t_final == pytest.approx((p["r0"] - p["eps"]) / (p["u"] - p["v"]), abs=1e-6)
        assert np.allclose(result.controls["theta"], 0.0, atol=1e-4)


def _zermelo_closed_form(rho: float) -> tuple[float, callable]:
    """Max-range Zermelo (eqs. 6.19–6.23, t_f = 1): lambda_1 = -1, lambda_2 = rho (t - 1/2), so
    tan u = rho (1/2 - t) (linear tangent law); x1(t_f) by quadrature of that control."""

    def heading(t):
        return np.arctan(rho * (0.5 - t))

    def x2(t):
        return quad(lambda s: np.sin(heading(s)), 0.0, t, epsabs=1e-13)[0]

    x1f = quad(lambda t: np.cos(heading(t)) + rho * x2(t), 0.0, 1.0, epsabs=1e-12, limit=200)[0]
    return x1f, heading


def test_zermelo_max_range_matches_the_linear_tangent_law() -> None:
    rho = 10.0
    x1f, heading = _zermelo_closed_form(rho)
    result = gamespec.solve(ZERMELO_RANGE)
    assert result.status == gamespec.Status.OPTIMAL
    assert result.objective == pytest.approx(x1f, rel=1e-6)
    assert np.max(np.abs(result.controls["u"] - heading(result.control_time))) < 1e-5
    t = result.arrays["costate_time"]
    assert np.max(np.abs(result.costates["lambda_x1"] + 1.0)) < 1e-6
    assert np.max(np.abs(result.costates["lambda_x2"] - rho * (t - 0.5))) < 1e-5


def test_trapezoidal_converges_at_second_order() -> None:
    x1f, _ = _zermelo_closed_form(10.0)
    errors = []
    for n in (10, 20, 40):
        spec = gamespec.load(ZERMELO_RANGE, ["method.scheme=trapezoidal", f"method.intervals={n}"])
        errors.append(abs(gamespec.solve(spec).objective - x1f))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.15), orders


def test_radau_error_falls_with_degree() -> None:
    x1f, _ = _zermelo_closed_form(10.0)
    errors = []
    for degree in (1, 2, 3):
        spec = gamespec.load(ZERMELO_RANGE, [f"method.degree={degree}", "method.intervals=10"])
        errors.append(abs(gamespec.solve(spec).objective - x1f))
    assert errors[0] > 100 * errors[1]
    assert errors[1] > 5 * errors[2]


def test_two_on_one_capture_is_simultaneous_with_zero_hamiltonian() -> None:
    """Theorem 2 and eqs. 2.22–2.23: r1(t_c) = r2(t_c) = eps and the thesis' H = -1 + λᵀf = 0
    along the optimal arc. gamespec states the cost in Mayer form (maximize t_f, i.e. minimize
    -t_f), whose Hamiltonian λᵀf equals -dΦ/dt_f = 1 on the arc: the same condition, which
    ``hamiltonian_end_error`` measures."""
    result = gamespec.solve(TWO_ON_ONE)
    eps = result.parameters["capture_radius"]
    assert result.status == gamespec.Status.OPTIMAL
    assert result.states["r1"][-1] == pytest.approx(eps, abs=1e-7)
    assert result.states["r2"][-1] == pytest.approx(eps, abs=1e-6)
    assert np.all(result.states["r1"][:-1] - result.states["r2"][:-1] != 0.0)
    assert result.checks["hamiltonian_end_error"] < 1e-3
    assert result.checks["max_defect"] < 1e-6
    assert result.checks["max_constraint_violation"] < 1e-7


def test_two_on_one_poor_guess_reaches_a_worse_local_optimum() -> None:
    """What the file's comment claims about its initial guess."""
    shipped = gamespec.solve(TWO_ON_ONE)
    poor = gamespec.solve(gamespec.load(TWO_ON_ONE, ["guess_heading=-1.5"]))
    assert poor.status == gamespec.Status.OPTIMAL
    assert poor.objective < shipped.objective - 0.1


def test_uniform_grid_two_on_one_is_caught_by_the_defect_check() -> None:
    """The re-integration check sees what the solver's own residuals do not."""
    result = gamespec.solve(gamespec.load(TWO_ON_ONE, ["method.grading=1", "guess_heading=-1.5"]))
    assert result.checks["max_defect"] > 1e-2


def test_min_time_hamiltonian_is_minus_one() -> None:
    """Free final time, Mayer cost t_f: H(t) = -dPhi/dt_f = -1 in the minimization form."""
    result = gamespec.solve(ZERMELO_TIME)
    assert result.status == gamespec.Status.OPTIMAL
    assert result.checks["hamiltonian_end_error"] < 1e-3
    assert result.states["x1"][-1] == pytest.approx(2.0, abs=1e-8)


def test_resolve_reuses_the_model_and_warm_starts() -> None:
    solver = gamespec.compile_spec(ZERMELO_TIME)
    first = solver.solve()
    again = solver.solve()
    assert again.iterations < first.iterations
    assert again.objective == pytest.approx(first.objective, rel=1e-7)
    nearby = solver.solve(parameters={"rho": 9.5})
    assert nearby.status == gamespec.Status.OPTIMAL
    assert nearby.build_time_s == first.build_time_s


def test_result_round_trip_and_guess_from_result(tmp_path) -> None:
    result = gamespec.solve(ZERMELO_TIME)
    result.save(tmp_path / "run")
    loaded = gamespec.Result.load(tmp_path / "run")
    assert loaded.summary() == result.summary()
    for field in ("states", "controls", "costates"):
        for name, values in getattr(result, field).items():
            np.testing.assert_array_equal(getattr(loaded, field)[name], values)
    fine = gamespec.load(ZERMELO_TIME, ["method.intervals=30", f"guess.result={tmp_path / 'run'}"])
    seeded = gamespec.solve(fine)
    cold = gamespec.solve(gamespec.load(ZERMELO_TIME, ["method.intervals=30"]))
    assert seeded.iterations < cold.iterations
    assert seeded.objective == pytest.approx(cold.objective, rel=1e-7)


@pytest.mark.parametrize(("scheme", "degree"), [("radau", 1), ("radau", 2), ("radau", 3), ("trapezoidal", 1)])
def test_minimum_energy_transfer_closed_form(tmp_path, scheme, degree) -> None:
    """min ∫ u² dt, x' = u, x(0) = 0, x(1) = 1: u = 1, J = 1, and the costate λ = -2u = -2 (from
    H = u² + λu); the Lagrange quadrature of every scheme must integrate it exactly."""
    path = tmp_path / "energy.yaml"
    path.write_text(
        "kind: optimal_control\n"
        "problem:\n"
        "  states: {x: {initial: 0, final: 1}}\n"
        "  controls: {u: {}}\n"
        "  dynamics: {x: u}\n"
        "  objective: {lagrange: u**2}\n"
        f"method: {{scheme: {scheme}, degree: {degree}, intervals: 5}}\n"
    )
    result = gamespec.solve(path)
    assert result.status == gamespec.Status.OPTIMAL
    assert result.objective == pytest.approx(1.0, abs=1e-8)
    assert np.allclose(result.controls["u"], 1.0, atol=1e-8)
    if scheme == "radau":
        assert np.allclose(result.costates["lambda_x"], -2.0, atol=1e-7)
