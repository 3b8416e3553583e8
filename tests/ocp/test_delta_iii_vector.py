"""The Delta III launch written with vectors (issue 25): the final state meets the target orbit's
five elements as an independent NumPy conversion from position and velocity computes them (so the
file's cross products, norms and dot products say what the header says), and the final mass is the
launch mass less every burn and drop (constant flows over the solved burn times)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import gamespec
from gamespec.specs.ocp import parameter_values
from tests.conftest import PROBLEMS

FILE = PROBLEMS / "ocp" / "delta_iii_launch_vector.yaml"


def _elements(r: np.ndarray, v: np.ndarray, mu: float) -> tuple[float, float, float, float, float]:
    """Semi-major axis, eccentricity, inclination, right ascension of the node and argument of
    periapsis of the orbit through (r, v) (Vallado, Fundamentals of Astrodynamics, RV2COE)."""
    h = np.cross(r, v)
    n = np.cross([0.0, 0.0, 1.0], h)
    e = np.cross(v, h) / mu - r / np.linalg.norm(r)
    a = 1 / (2 / np.linalg.norm(r) - v @ v / mu)
    inclination = math.acos(h[2] / np.linalg.norm(h))
    node = math.acos(n[0] / np.linalg.norm(n))
    node = node if n[1] >= 0 else 2 * math.pi - node
    periapsis = math.acos(n @ e / (np.linalg.norm(n) * np.linalg.norm(e)))
    periapsis = periapsis if e[2] >= 0 else 2 * math.pi - periapsis
    return float(a), float(np.linalg.norm(e)), inclination, node, periapsis


@pytest.mark.slow
def test_delta_iii_vector_file_reaches_its_orbit_with_the_mass_its_burns_leave() -> None:
    result = gamespec.solve(FILE)
    assert result.status == gamespec.Status.OPTIMAL, result.message
    assert all(result.metrics["checks_passed"].values())
    p = parameter_values(gamespec.load(FILE).problem.parameters)
    r = np.array([result.states[f"r__{i}"][-1] for i in range(3)])
    v = np.array([result.states[f"v__{i}"][-1] for i in range(3)])
    a, e, inclination, node, periapsis = _elements(r, v, p["mu"])
    assert a == pytest.approx(p["a_f"], rel=1e-8)
    assert e == pytest.approx(p["e_f"], abs=1e-8)
    for angle, target in ((inclination, "i_f"), (node, "Om_f"), (periapsis, "om_f")):
        assert angle == pytest.approx(p[target], abs=1e-7)
    g0 = p["g0"]
    srb, first, second = (p[f"T_{s}"] / (g0 * p[f"isp_{s}"]) for s in ("srb", "1", "2"))
    burn = result.metrics["phases"][-1]["duration"]
    burned = 75.2 * (9 * srb + 2 * first) + 110.6 * first + burn * second
    expected = p["m_launch"] - burned - 9 * p["dry_srb"] - p["dry_1"]
    assert result.objective == pytest.approx(expected, rel=1e-9)
