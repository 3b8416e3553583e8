"""The classic optimal-control benchmarks of ``problems/ocp/`` solve, on casadi and on pyomo, to
within a stated tolerance of a reference value whose origin and precision each file records (issue
17, items 8 and 9).

A reference is a closed form (exact: computed here), a value printed in a source (known to half a unit
of its last printed digit), or, where the printed values belong to another discretization (COPS
tabulates the optimum of its own trapezoidal or collocation NLP) or the source could not be read, an
independent computation: 400 LGR intervals of degree 3 on casadi and on pyomo, which agree, known to
the change from 200 to 400 intervals. The tolerance of each check is

    precision of the reference + 2 |J_N - J_2N| + tol * (number of complementarity pairs),

the second term the mesh's own error estimate at the file's N (for a method of order p >= 1 in its
asymptotic range ``J_N - J* = (J_N - J_2N) / (1 - 2**-p)``, at most twice the change on doubling;
J_2N is solved here, on casadi, at a tenth of the tolerance), the third the duality gap
``sum z_i s_i`` an interior-point method stops with, each bound or inequality contributing at most its
complementarity tolerance (IPOPT's ``tol``, 1e-8): on a bang-bang or singular problem with hundreds of
active bounds it is the largest term (catalyst mixing, 50 intervals: 300 bounds).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np
import pytest
from scipy.optimize import brentq

import gamespec
from gamespec.ocp.transcription import Transcription
from tests.conftest import PROBLEMS

TOL = 1e-8
"""IPOPT's ``tol`` in every benchmark file (the default)."""

MESH_CHECKS = {"max_defect_relative", "chattering"}
"""Checks that measure the file's mesh rather than the solver's convergence."""


def _brachistochrone_time(dx: float = 10.0, drop: float = 5.0, g: float = 9.80665) -> float:
    """The cycloid x = r (phi - sin phi), drop = r (1 - cos phi) through the end point: t = phi sqrt(r/g)."""
    phi = brentq(lambda p: (p - math.sin(p)) / (1 - math.cos(p)) - dx / drop, 1e-6, 2 * math.pi - 1e-6)
    r = drop / (1 - math.cos(phi))
    return phi * math.sqrt(r / g)


def _linear_tangent_time(a: float = 100.0, speed: float = 45.0, height: float = 5.0) -> float:
    """Particle steering (Bryson & Ho §2.4): y1 free at the end, so lambda_1 = 0, lambda_3 constant,
    lambda_4 linear in t and ``tan u = tan u0 - c t`` (the linear tangent law). With s = tan u, dt =
    -ds/c: y4(t_f) = (a/c)(sqrt(1 + s0^2) - sqrt(1 + sf^2)) = 0 gives sf = -s0 and t_f = 2 s0 / c;
    y3(t_f) = a t_f asinh(s0)/s0 = speed; y2(t_f) = a t_f^2 (s0 sqrt(1 + s0^2) - asinh(s0)) / (4 s0^2)
    = height: one equation in s0 (|u| < pi/2 throughout, so the bound is inactive)."""

    def height_gap(s: float) -> float:
        return speed**2 / (4 * a * math.asinh(s) ** 2) * (s * math.sqrt(1 + s * s) - math.asinh(s)) - height

    s0 = brentq(height_gap, 1e-6, 1e3, xtol=1e-15)
    return speed * s0 / (a * math.asinh(s0))


@dataclass(frozen=True)
class Reference:
    """A reference objective, the absolute precision it is known to, and where it comes from."""

    value: float
    precision: float
    source: str


REFERENCES = {
    "brachistochrone": Reference(_brachistochrone_time(), 0.0, "closed form: the cycloid"),
    "bryson_denham": Reference(4 / (9 * (1 / 9)), 0.0, "closed form: J = 4/(9 l) for l <= 1/6"),
    "min_time_double_integrator": Reference(2.0, 0.0, "closed form: t_f = 2 sqrt(x0)"),
    "particle_steering": Reference(_linear_tangent_time(), 0.0, "closed form: the linear tangent law"),
    "hang_glider": Reference(1248.03103, 0.5e-5, "Betts, example 10.54, as printed"),
    "goddard_rocket": Reference(1.0128369, 1e-7, "Radau (O(h), above) and trapezoid (below) agreeing"),
    "robot_arm": Reference(9.140913, 4.4e-6, "400 intervals, casadi and pyomo"),
    "catalyst_mixing": Reference(-4.8055683e-2, 2e-9, "400 intervals, casadi and pyomo"),
    "free_flying_robot": Reference(7.910158, 1.2e-4, "400 intervals, casadi and pyomo"),
}
"""What each file's header says, in numbers (the files say how each was found)."""


def _file(name: str) -> str:
    return str(PROBLEMS / "ocp" / f"{name}.yaml")


@cache
def _solved(name: str, backend: str) -> gamespec.Result:
    return gamespec.solve(_file(name), backend)


@cache
def _mesh_error(name: str) -> float:
    """``2 |J_N - J_2N|`` at the file's N (casadi)."""
    spec = gamespec.load(_file(name))
    doubled = [f"method.intervals={2 * spec.method.intervals}", f"solver.options.nlp.tol={TOL / 10}"]
    fine = gamespec.solve(gamespec.load(_file(name), doubled), "casadi")
    assert fine.ok, fine.message
    return 2 * abs(_solved(name, "casadi").objective - fine.objective)


@cache
def _duality_gap_bound(name: str) -> float:
    """``tol`` times the number of complementarity pairs: finite bounds of the variables that are not
    fixed, and the finite sides of the path constraints at every evaluation point."""
    tr = Transcription(gamespec.load(_file(name)))
    b = tr.bounds(tr.ocp.parameter_values())
    pairs = 0
    for lower, upper in ((b.x_lower, b.x_upper), (b.u_lower, b.u_upper), (b.d_lower, b.d_upper)):
        free = lower != upper
        pairs += int(np.sum(np.isfinite(lower) & free) + np.sum(np.isfinite(upper) & free))
    if tr.free_time:
        pairs += int(np.isfinite(b.t_lower)) + int(np.isfinite(b.t_upper))
    inequalities = [r for r in tr.ocp.path if not r.is_equality]
    sides = sum(int(np.isfinite(r.lower)) + int(np.isfinite(r.upper)) for r in inequalities)
    return TOL * (pairs + sides * len(tr.grid.eval_index))


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
@pytest.mark.parametrize("name", list(REFERENCES))
def test_benchmark_meets_its_reference(name: str, backend: str) -> None:
    reference = REFERENCES[name]
    result = _solved(name, backend)
    assert result.ok, result.message
    # the solver converged; the file's mesh may be too coarse for a relative defect of 1e-6 (hang
    # glider, Goddard, free-flying robot: ``feasible``, the message names the check), and Goddard's
    # singular arc chatters: those checks alone may keep a file from ``optimal``
    assert {f.name for f in result.failed_checks()} <= MESH_CHECKS, result.message
    assert (result.status == gamespec.Status.OPTIMAL) == (not result.failed_checks())
    assert result.checks["max_constraint_violation"] < 1e-6
    tolerance = reference.precision + _mesh_error(name) + _duality_gap_bound(name)
    assert abs(result.objective - reference.value) <= tolerance, reference.source


@pytest.mark.parametrize("name", list(REFERENCES))
def test_both_backends_reach_the_same_optimum_of_the_same_nlp(name: str) -> None:
    casadi, pyomo = _solved(name, "casadi"), _solved(name, "pyomo")
    assert abs(casadi.objective - pyomo.objective) <= 2 * _duality_gap_bound(name)


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_particle_steering_from_a_flat_guess_converges_in_tens_of_iterations(backend: str) -> None:
    """The file starts from u = 0 (the COPS start). IPOPT with MUMPS's default permuting scaling
    stalled there for 3000 iterations on a miscounted KKT inertia; an interior-point method on this
    smooth 750-variable NLP needs tens (ripopt: 19)."""
    spec = gamespec.load(_file("particle_steering"))
    tr = Transcription(spec)
    assert np.all(tr.guess(tr.ocp.parameter_values()).U == 0.0)
    result = _solved("particle_steering", backend)
    assert result.status == gamespec.Status.OPTIMAL
    assert result.iterations is not None and result.iterations <= 100
