"""OCP checks that tell the truth (issue 23, item 6; issue 25, item 5): a NaN defect fails and
makes refinement split its interval, so the hyper-sensitive problem converges from 10 intervals;
the Hamiltonian includes the integral constraints' multipliers (hanging chain) and is left out, with
the reason, where H need not be constant; refinement works on a problem without controls."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import fsolve

import gamespec
from gamespec.compiling.refinement import refined_mesh, trajectory_of
from gamespec.loader import spec_from_dict
from gamespec.ocp.checks import hamiltonian
from gamespec.ocp.transcription import Transcription
from gamespec.specs.ocp import RefineSpec
from tests.conftest import PROBLEMS

HYPER_SENSITIVE = PROBLEMS / "ocp" / "hyper_sensitive.yaml"
HANGING_CHAIN = PROBLEMS / "ocp" / "hanging_chain.yaml"


def _layers_value(x0: float, xf: float) -> float:
    """The hyper-sensitive optimum for t_f >> 1: the infinite-horizon values of its two boundary
    layers, V(x0) + W(xf), from the HJB equation 1/2 x^2 - 1/2 V'^2 - V' x^3 = 0 of each layer:
    V' = -x^3 + sqrt(x^6 + x^2) (decay to 0), W' = x^3 + sqrt(x^6 + x^2) (rise from 0), integrated
    in closed form with F(x) = int_0^x s sqrt(s^4 + 1) ds = (w sqrt(w^2 + 1) + asinh w) / 4, w = x^2."""

    def F(x: float) -> float:
        w = x * x
        return (w * math.sqrt(w * w + 1) + math.asinh(w)) / 4

    return F(x0) - x0**4 / 4 + F(xf) + xf**4 / 4


def test_the_layers_value_is_the_published_optimum() -> None:
    """Rao & Mease's J* = 3.3620569 (printed to 8 digits) for x(0) = 1, x(t_f) = 1.5."""
    assert _layers_value(1.0, 1.5) == pytest.approx(3.3620569, abs=0.5e-7)


@pytest.mark.parametrize("ends", [(1.0, 1.5), (1.5, 1.0)])
def test_hyper_sensitive_from_ten_intervals_reaches_its_optimum(ends: tuple[float, float]) -> None:
    """From 10 intervals of length 1000 (the RK4 re-integration of the boundary layers overflows:
    NaN defects) the hp refinement reaches J* to 1e-6 and says ``optimal``; both orders of the end
    values (Rao & Mease's, and GPOPS-II's example file's)."""
    x0, xf = ends
    sets = [f"problem.states.x.initial={x0}", f"problem.states.x.final={xf}"]
    result = gamespec.solve(gamespec.load(HYPER_SENSITIVE, sets))
    history = result.metrics["refinement"]
    assert history[0]["intervals"] == 10 and math.isnan(history[0]["max_defect_relative"])
    assert result.status is gamespec.Status.OPTIMAL, result.message
    assert result.metrics["refinement_converged"]
    assert result.objective == pytest.approx(_layers_value(x0, xf), rel=1e-6)


def test_a_nan_defect_fails_its_verdict_and_halves_its_interval() -> None:
    options = RefineSpec(strategy="hp", tolerance=1e-6)
    breaks, degrees = np.array([0.0, 0.5, 1.0]), np.array([3, 3])
    mesh, new_degrees = refined_mesh(breaks, degrees, np.array([math.nan, 1e-9]), options, 3)
    assert mesh == [0.0, 0.25, 0.5, 1.0] and new_degrees == [3, 3, 3]
    coarse = gamespec.solve(gamespec.load(HYPER_SENSITIVE, ["method.refine=null"]))
    assert math.isnan(coarse.checks["max_defect"])
    assert coarse.metrics["checks_passed"]["max_defect_relative"] is False
    assert coarse.status is gamespec.Status.FEASIBLE and "not computable" in coarse.message


def _catenary() -> tuple[float, float, float, float]:
    """The hanging chain's catenary x = c cosh((t - m)/c) + k through (0, a), (1, b) of length L
    (COPS data), and its potential energy int x cosh((t - m)/c) dt."""
    a, b, length = 1.0, 3.0, 4.0

    def gaps(p: np.ndarray) -> list[float]:
        c, m, k = p
        return [
            c * math.cosh(-m / c) + k - a,
            c * math.cosh((1 - m) / c) + k - b,
            c * (math.sinh((1 - m) / c) + math.sinh(m / c)) - length,
        ]

    c, m, k = fsolve(gaps, [0.3, 0.4, -1.0], xtol=1e-12)
    energy = quad(lambda t: (c * math.cosh((t - m) / c) + k) * math.cosh((t - m) / c), 0, 1, epsabs=1e-14)[0]
    return c, m, k, energy


def test_the_hanging_chain_hamiltonian_includes_the_integral_multiplier() -> None:
    """On the catenary H = x sqrt(1 + u^2) + lambda u + nu sqrt(1 + u^2) is constant; without the
    length constraint's nu it is not (it varies as sqrt(1 + u^2) does)."""
    *_, energy = _catenary()
    variations = []
    for n in (100, 300):
        spec = gamespec.load(HANGING_CHAIN, [f"method.intervals={n}"])
        result = gamespec.solve(spec, "casadi")
        assert result.status is gamespec.Status.OPTIMAL, result.message
        assert result.objective == pytest.approx(energy, rel=1e-8)
        variations.append(result.checks["hamiltonian_variation"])
    assert variations[1] < variations[0] / 10 and variations[1] < 1e-4
    tr = Transcription(spec)
    sol, values = trajectory_of(tr, result)
    lam = np.array([result.costates["lambda_x"]])
    without = hamiltonian(tr, sol, values, lam)
    assert np.ptp(without) > 1e3 * variations[1]


def _rider(path_constraint: str) -> dict:
    """A small problem with one path constraint: x' = u, min int u^2 + x^2, x(0) = 0, x(2) = 0."""
    return {
        "kind": "optimal_control",
        "name": "rider",
        "problem": {
            "states": {"x": {"initial": 0.0, "final": 0.0}},
            "controls": {"u": {}},
            "dynamics": {"x": "u"},
            "objective": {"lagrange": "u**2 + x**2"},
            "path_constraints": [path_constraint],
            "time": {"final": 2.0},
        },
        "method": {"intervals": 20},
    }


def test_the_hamiltonian_is_left_out_with_the_reason_under_a_time_dependent_path_constraint() -> None:
    """The Alp rider's kind of constraint: x >= a bump in t. Its multiplier makes dH/dt = nu dc/dt."""
    bumped = gamespec.solve(spec_from_dict(_rider("x >= exp(-10*(t - 1)**2) - exp(-10)")))
    assert bumped.ok
    assert "hamiltonian_variation" not in bumped.checks
    assert "depends on t" in bumped.metrics["checks_skipped"]["hamiltonian_variation"]
    still = gamespec.solve(spec_from_dict(_rider("x >= -1")))
    assert "hamiltonian_variation" in still.checks and "checks_skipped" not in still.metrics


def test_refinement_works_without_controls() -> None:
    """x' = -k x with k a design variable fitting x(1) = e^-2: no controls, a mesh refined to 1e-10."""
    data = {
        "kind": "optimal_control",
        "name": "decay",
        "problem": {
            "design": {"k": {"lower": 0.0, "upper": 10.0, "guess": 1.0}},
            "states": {"x": {"initial": 1.0}},
            "dynamics": {"x": "-k*x"},
            "objective": {"mayer": "(x_f - exp(-2))**2"},
            "time": {"final": 1.0},
        },
        "method": {"intervals": 2, "degree": 2, "refine": {"tolerance": 1e-10}},
    }
    result = gamespec.solve(spec_from_dict(data))
    assert result.ok and result.metrics["refinement_converged"]
    assert len(result.metrics["refinement"]) > 1
    assert result.metrics["design"]["k"] == pytest.approx(2.0, rel=1e-6)


def test_hp_raises_the_degree_only_where_the_defect_decays_as_the_ph_rule_assumes() -> None:
    """Both intervals went from degree 3 to 5 (the ph rule predicts a factor 3**2 = 9, so at least
    3 is needed): the first fell by 100 and gets a higher degree, the second by 2 and is split."""
    options = RefineSpec(strategy="hp", tolerance=1e-8, max_degree=12)  # 12 is in reach of both
    breaks, degrees = np.array([0.0, 0.5, 1.0]), np.array([5, 5])
    before = {(0.0, 0.5): (3, 1e-3), (0.5, 1.0): (3, 1e-3)}
    mesh, new_degrees = refined_mesh(breaks, degrees, np.array([1e-5, 5e-4]), options, 3, before)
    assert mesh[:2] == [0.0, 0.5] and new_degrees[0] > 5
    assert len(mesh) > 3 and new_degrees[1:] == [3] * (len(mesh) - 2)


def test_a_chain_that_bends_between_quadrature_points_is_not_optimal() -> None:
    """From a deeper parabola on 50 intervals IPOPT stops at a spurious NLP minimum below the
    catenary's energy (the chain drops steeply inside its first interval, between the Radau points,
    so the quadrature counts little of that length). The re-integrated length is not L: the
    constraint violation check fails and the status says so."""
    *_, energy = _catenary()
    deep = [
        "method.intervals=50",
        "guess.states.x=1 + 2*tau - 6*tau*(1 - tau)",
        "guess.controls.u=2 - 6*(1 - 2*tau)",
    ]
    result = gamespec.solve(gamespec.load(HANGING_CHAIN, deep), "casadi")
    assert result.objective < energy - 0.1  # below the optimum: not a chain of length L
    assert result.checks["max_constraint_violation"] > 0.1
    assert result.status is gamespec.Status.FEASIBLE and "max_constraint_violation" in result.message
