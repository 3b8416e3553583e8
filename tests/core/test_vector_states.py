"""Vector states and controls, and definitions at the ends (issue 25, item 3): a vector problem
equals its scalar form written out by hand, a closed form, and the refusals that keep a file
meaning one thing."""

from __future__ import annotations

import numpy as np
import pytest

import gamespec
from gamespec.errors import SpecError
from gamespec.loader import spec_from_dict
from tests.conftest import PROBLEMS


def _spec(problem: dict, **extra: object) -> gamespec.SpecBase:
    return spec_from_dict({"kind": "optimal_control", "name": "v", "problem": problem, **extra})


def _solved(problem: dict) -> gamespec.Result:
    result = gamespec.solve(_spec(problem, method={"intervals": 12}))
    assert result.status == "optimal", result.message
    return result


def test_a_planar_double_integrator_meets_its_closed_form() -> None:
    """min ∫ u·u dt from rest at 0 to rest at d in time T: each axis gives 12 d_i²/T³."""
    d, T = np.array([1.0, -0.5]), 2.0
    result = _solved(
        {
            "states": {
                "r": {"size": 2, "initial": 0, "final": list(d)},
                "v": {"size": 2, "initial": 0, "final": 0},
            },
            "controls": {"u": {"size": 2}},
            "dynamics": {"r": "v", "v": "u"},
            "objective": {"lagrange": "dot(u, u)"},
            "time": {"final": T},
        }
    )
    assert result.objective == pytest.approx(12 * float(d @ d) / T**3, rel=1e-9)
    assert set(result.states) == {"r__0", "r__1", "v__0", "v__1"}


VECTOR = {
    "parameters": {"w": 0.7},
    "definitions": {"a": "cross(omega, r) - 0.1*v", "speed": "norm(v)"},
    "states": {
        "r": {"size": 3, "initial": [1, 0, 0.5]},
        "v": {"size": 3, "initial": "[0, w, 0]"},
        "omega": {"size": 3, "initial": [0, 0, 1]},
    },
    "controls": {"u": {"size": 3, "lower": -2, "upper": [2, 2, 1]}},
    "dynamics": {"r": "v", "v": "a + u", "omega": "[0, 0, 0]"},
    "objective": {"lagrange": "dot(u, u)/2 + 0.01*speed", "mayer": "norm(r_f - [0, 1, 0])**2"},
    "time": {"final": 1.5},
    "path_constraints": ["-1.5 <= v[2] <= 1.5"],
    "boundary_constraints": ["r_f[2] == 0"],
}

SCALAR = {
    "parameters": {"w": 0.7},
    "definitions": {
        "a0": "omega1*r2 - omega2*r1 - 0.1*v0",
        "a1": "omega2*r0 - omega0*r2 - 0.1*v1",
        "a2": "omega0*r1 - omega1*r0 - 0.1*v2",
        "speed": "sqrt(v0**2 + v1**2 + v2**2)",
    },
    "states": {
        **{f"r{i}": {"initial": x} for i, x in enumerate([1, 0, 0.5])},
        **{f"v{i}": {"initial": x} for i, x in enumerate([0, "w", 0])},
        **{f"omega{i}": {"initial": x} for i, x in enumerate([0, 0, 1])},
    },
    "controls": {f"u{i}": {"lower": -2, "upper": hi} for i, hi in enumerate([2, 2, 1])},
    "dynamics": {
        **{f"r{i}": f"v{i}" for i in range(3)},
        **{f"v{i}": f"a{i} + u{i}" for i in range(3)},
        **{f"omega{i}": 0 for i in range(3)},
    },
    "objective": {
        "lagrange": "(u0**2 + u1**2 + u2**2)/2 + 0.01*speed",
        "mayer": "r0_f**2 + (r1_f - 1)**2 + r2_f**2",
    },
    "time": {"final": 1.5},
    "path_constraints": ["-1.5 <= v2 <= 1.5"],
    "boundary_constraints": ["r2_f == 0"],
}


def test_a_vector_problem_equals_its_scalar_form() -> None:
    vector, scalar = _solved(VECTOR), _solved(SCALAR)
    assert vector.objective == pytest.approx(scalar.objective, rel=1e-10, abs=1e-12)
    for name in ("r", "v", "omega"):
        for i in range(3):
            np.testing.assert_allclose(vector.states[f"{name}__{i}"], scalar.states[f"{name}{i}"], atol=1e-8)
    np.testing.assert_allclose(vector.controls["u__2"], scalar.controls["u2"], atol=1e-8)


def test_a_vector_constraint_is_one_per_component() -> None:
    spec = _spec(
        {**VECTOR, "boundary_constraints": ["r_f == [0, 1, 0]"], "path_constraints": ["-1 <= u <= 1"]}
    )
    assert spec.problem.boundary_constraints == ["r__0_f == 0", "r__1_f - 1 == 0", "r__2_f == 0"]
    assert len(spec.problem.path_constraints) == 6


@pytest.mark.parametrize(
    ("change", "field", "reason"),
    [
        (
            {"states": {**VECTOR["states"], "r": {"size": 3, "initial": [1, 0]}}},
            "problem.states.r.initial",
            "2 values",
        ),
        ({"dynamics": {**VECTOR["dynamics"], "v": "sin(v)"}}, "problem.dynamics.v", "takes scalars"),
        ({"dynamics": {**VECTOR["dynamics"], "v": "r*v"}}, "problem.dynamics.v", "dot\\(a, b\\)"),
        ({"dynamics": {**VECTOR["dynamics"], "omega": "[0, 0]"}}, "problem.dynamics.omega", "size 2, not 3"),
        ({"definitions": {"a": "r[3]", "speed": "1"}}, "problem.definitions.a", "out of range"),
        ({"objective": {"lagrange": "u"}}, "problem.objective.lagrange", "vector where a scalar"),
        ({"states": {**VECTOR["states"], "r": {"size": 0}}}, "problem.states.r.size", "integer from 1"),
    ],
)
def test_a_vector_misuse_names_its_field(change: dict, field: str, reason: str) -> None:
    with pytest.raises(SpecError, match=reason) as err:
        _spec({**VECTOR, **change})
    assert err.value.field == field


def test_indexing_is_only_for_vectors() -> None:
    with pytest.raises(SpecError, match="only allowed over vector states"):
        _spec({**SCALAR, "objective": {"lagrange": "u0[0]"}})


def test_a_definition_at_the_ends_equals_it_written_out() -> None:
    """``e_f`` and ``e_0`` in the Mayer term and a boundary constraint: the definition over the end
    values (``t`` at the ends too)."""
    base = {
        "parameters": {"a": 0.8},
        "states": {"x": {"initial": 0.2}, "v": {"initial": 0}},
        "controls": {"u": {}},
        "dynamics": {"x": "v", "v": "u"},
        "objective": {"lagrange": "u**2/2"},
        "time": {"final": 1.5},
    }
    named = {
        **base,
        "definitions": {"e": "x**2 + v**2 + 0*t", "g": "e*(1 + t)"},
        "objective": {**base["objective"], "mayer": "10*(e_f - a)**2"},
        "boundary_constraints": ["g_f >= 2.5*g_0"],
    }
    written = {
        **base,
        "objective": {**base["objective"], "mayer": "10*(x_f**2 + v_f**2 - a)**2"},
        "boundary_constraints": ["(x_f**2 + v_f**2)*(1 + t_f) >= 2.5*(x_0**2 + v_0**2)"],
    }
    one, two = _solved(named), _solved(written)
    assert one.objective == pytest.approx(two.objective, rel=1e-10)
    np.testing.assert_allclose(one.states["x"], two.states["x"], atol=1e-9)


def test_a_file_without_vectors_is_read_as_written() -> None:
    spec = _spec(SCALAR)
    assert spec.problem.definitions["speed"] == SCALAR["definitions"]["speed"]


def _phases(problem: dict) -> gamespec.SpecBase:
    return spec_from_dict(
        {"kind": "multiphase_optimal_control", "problem": problem, "method": {"intervals": 6}}
    )


def test_vector_phases_equal_their_scalar_form() -> None:
    """Two phases of a planar double integrator with a jump of the velocity, a phase's own vector
    end constraint and a link by name, vector against scalar."""
    vector = {
        "states": {
            "r": {"size": 2, "initial": 0, "final": [1, 0.5]},
            "v": {"size": 2, "initial": 0, "final": 0},
        },
        "controls": {"u": {"size": 2}},
        "dynamics": {"r": "v", "v": "u"},
        "objective": {"lagrange": "dot(u, u)"},
        "boundary_constraints": ["phases.second.r_0[1] >= 0.3"],
        "phases": [
            {"name": "first", "duration": 1.0, "boundary_constraints": ["dot(v_f, v_f) <= 0.64"]},
            {"name": "second", "duration": 1.0, "jump": {"v": "v_f + [0.1, 0]"}},
        ],
    }
    scalar = {
        "states": {
            "r0": {"initial": 0, "final": 1},
            "r1": {"initial": 0, "final": 0.5},
            "v0": {"initial": 0, "final": 0},
            "v1": {"initial": 0, "final": 0},
        },
        "controls": {"u0": {}, "u1": {}},
        "dynamics": {"r0": "v0", "r1": "v1", "v0": "u0", "v1": "u1"},
        "objective": {"lagrange": "u0**2 + u1**2"},
        "boundary_constraints": ["phases.second.r1_0 >= 0.3"],
        "phases": [
            {"name": "first", "duration": 1.0, "boundary_constraints": ["v0_f**2 + v1_f**2 <= 0.64"]},
            {"name": "second", "duration": 1.0, "jump": {"v0": "v0_f + 0.1"}},
        ],
    }
    one, two = gamespec.solve(_phases(vector)), gamespec.solve(_phases(scalar))
    assert one.ok and two.ok
    assert one.objective == pytest.approx(two.objective, rel=1e-10)
    np.testing.assert_allclose(one.states["v__0"], two.states["v0"], atol=1e-8)


def test_vector_orbit_raising_equals_its_polar_form() -> None:
    """The shipped Cartesian vector file against Bryson & Ho's polar form (scalar states r, vr,
    vt, thrust angle phi): the same maximum radius on the same mesh (the two transcriptions differ,
    so to the discretization error), and the same radius history. (The polar form is only
    ``feasible`` on this mesh: its re-integration check sees the fast turn of the thrust angle.)"""
    intervals = ["method.intervals=20"]
    vector = gamespec.solve(gamespec.load(PROBLEMS / "ocp" / "orbit_raising_vector.yaml", intervals))
    polar = {
        "parameters": {"mu": 1.0, "T": 0.1405, "mdot": 0.0749},
        "definitions": {"m": "1 - mdot*t"},
        "states": {"r": {"initial": 1, "lower": 0.5}, "vr": {"initial": 0, "final": 0}, "vt": {"initial": 1}},
        "controls": {"phi": {}},
        "dynamics": {"r": "vr", "vr": "vt**2/r - mu/r**2 + T*sin(phi)/m", "vt": "-vr*vt/r + T*cos(phi)/m"},
        "boundary_constraints": ["vt_f**2*r_f == mu"],
        "objective": {"sense": "maximize", "mayer": "r_f"},
        "time": {"final": 3.32},
    }
    scalar = gamespec.solve(_spec(polar, method={"intervals": 20}, guess={"states": {"r": 1, "vt": 1}}))
    assert vector.status == "optimal" and scalar.ok
    assert vector.objective == pytest.approx(scalar.objective, rel=1e-4)
    radius = np.hypot(vector.states["r__0"], vector.states["r__1"])
    np.testing.assert_allclose(radius, np.interp(vector.time, scalar.time, scalar.states["r"]), atol=1e-3)


def test_a_component_name_given_by_the_file_is_refused() -> None:
    """A state ``r__0`` beside the vector ``r`` would replace its component (found in review)."""
    states = {**VECTOR["states"], "r__0": {"initial": 7}}
    with pytest.raises(SpecError, match="names used twice"):
        _spec({**VECTOR, "states": states, "dynamics": {**VECTOR["dynamics"], "r__0": 1}})
    with pytest.raises(SpecError, match="names used twice"):
        _spec({**VECTOR, "definitions": {**VECTOR["definitions"], "a__0": "1"}})


def test_what_names_no_vector_is_kept_as_written() -> None:
    """SymPy would simplify ``x/x`` to 1 and drop its singularity: a text without vectors is kept."""
    spec = _spec(
        {**VECTOR, "parameters": {"w": 0.7, "k": 2.0}, "definitions": {**VECTOR["definitions"], "q": "k/k"}}
    )
    assert spec.problem.definitions["q"] == "k/k"


def test_scale_and_a_free_initial_time_in_a_vector_file() -> None:
    problem = {
        **VECTOR,
        "controls": {"u": {"size": 3, "lower": -2, "upper": 2, "scale": "auto"}},
        "time": {"initial": "free", "initial_bounds": [0, 0.5], "final": 1.5},
        "boundary_constraints": ["r_f[2] == 0", "t_0 >= 0.1"],
    }
    spec = _spec(problem)
    assert spec.problem.controls["u__1"].scale == "auto"
    assert "t_0 >= 0.1" in spec.problem.boundary_constraints


def test_a_multiphase_file_has_no_definitions_at_the_ends() -> None:
    """A phase may replace a definition, so ``h_f`` of a multi-phase file would be ambiguous: it is
    an undefined name, with vectors as without."""
    problem = {
        "states": {"r": {"size": 2, "initial": 0}},
        "controls": {"u": {"size": 2}},
        "dynamics": {"r": "u"},
        "definitions": {"h": "r[0] + t"},
        "objective": {"mayer": "h_f", "lagrange": "dot(u, u)"},
        "phases": [
            {"name": "a", "duration": 1.0},
            {"name": "b", "duration": 1.0, "definitions": {"h": "r[1]"}},
        ],
    }
    with pytest.raises(SpecError, match="undefined symbol 'h_f'"):
        _phases(problem)


@pytest.mark.parametrize(
    "change",
    [
        {"states": ["x"]},
        {"definitions": [1, 2]},
        {"definitions": {"h": [1, 2]}},
        {"path_constraints": [[1]]},
        {"integral_constraints": [5]},
        {"time": "x"},
        {"time": {"initial": float("inf")}},
    ],
)
def test_a_malformed_vector_file_is_one_schema_error(change: dict) -> None:
    with pytest.raises(SpecError):
        _spec({**VECTOR, **change})
