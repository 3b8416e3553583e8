"""Vector states with tables, interior points (``at:``, ``r(t=...)``), measurements and a free
event (issue 25, item 3): each vector file equals its scalar form written out by hand (objective to
1e-10, the same trajectory), the closed forms of ``tests/ocp/test_interior.py`` per component, and
the refusals that remain."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import gamespec
from gamespec.errors import SpecError
from gamespec.loader import spec_from_dict

A, T = np.array([0.7, -0.4]), 2.0
CLOSED_FORM = 192 * float(A @ A) / T**3
"""min ∫ u·u, r'' = u, rest to rest at 0 on [0, T] through r(T/2) = a: each axis is the
double integrator forced through a_i at T/2 (tests/ocp/test_interior.py), 192 a_i²/T³."""


def _planar(**problem: object) -> dict:
    return {
        "kind": "optimal_control",
        "problem": {
            "parameters": {"a0": float(A[0]), "a1": float(A[1])},
            "states": {
                "r": {"size": 2, "initial": 0, "final": 0},
                "v": {"size": 2, "initial": 0, "final": 0},
            },
            "controls": {"u": {"size": 2}},
            "dynamics": {"r": "v", "v": "u"},
            "objective": {"lagrange": "dot(u, u)"},
            "time": {"final": T},
            **problem,
        },
        "method": {"intervals": 10, "degree": 3},
    }


def _planar_scalar(**problem: object) -> dict:
    rest = {"initial": 0, "final": 0}
    return {
        "kind": "optimal_control",
        "problem": {
            "parameters": {"a0": float(A[0]), "a1": float(A[1])},
            "states": {"r0": rest, "r1": rest, "v0": rest, "v1": rest},
            "controls": {"u0": {}, "u1": {}},
            "dynamics": {"r0": "v0", "r1": "v1", "v0": "u0", "v1": "u1"},
            "objective": {"lagrange": "u0**2 + u1**2"},
            "time": {"final": T},
            **problem,
        },
        "method": {"intervals": 10, "degree": 3},
    }


def _solve(data: dict, backend: str = "casadi") -> gamespec.Result:
    result = gamespec.solve(spec_from_dict(data), backend=backend)
    assert result.status == gamespec.Status.OPTIMAL, result.message
    return result


def _same(vector: gamespec.Result, scalar: gamespec.Result, names: dict[str, str]) -> None:
    assert vector.objective == pytest.approx(scalar.objective, rel=1e-10, abs=1e-12)
    for component, name in names.items():
        np.testing.assert_allclose(vector.states[component], scalar.states[name], atol=1e-8)


POINT = {"r__0": "r0", "r__1": "r1", "v__0": "v0", "v__1": "v1"}
SCALAR_AT = {"at": [{"time": T / 2, "constraints": ["r0 == a0", "r1 == a1"]}]}


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
@pytest.mark.parametrize(
    "point",
    [
        {"at": [{"time": T / 2, "constraints": ["r == [a0, a1]"]}]},
        {"boundary_constraints": ["r(t=1) == [a0, a1]"]},
        {"boundary_constraints": ["r(t=1)[0] == a0", "r(t=1)[-1] == a1"]},
    ],
    ids=["at", "vector at a time", "components at a time"],
)
def test_a_planar_double_integrator_through_a_point(point: dict, backend: str) -> None:
    vector = _solve(_planar(**point), backend)
    assert vector.objective == pytest.approx(CLOSED_FORM, rel=1e-9)
    _same(vector, _solve(_planar_scalar(**SCALAR_AT), backend), POINT)


def test_vector_interior_points_are_their_components() -> None:
    spec = spec_from_dict(
        _planar(
            at=[{"time": 1.0, "constraints": ["dot(r, v) == 0", "-1 <= r <= 1"]}],
            boundary_constraints=["norm(r(t=0.5)) <= 2*r_f[0] + 1"],
        )
    )
    assert spec.problem.at[0].constraints == [
        "r__0*v__0 + r__1*v__1 == 0",
        "r__0 >= -1.0",
        "r__0 <= 1.0",
        "r__1 >= -1.0",
        "r__1 <= 1.0",
    ]
    assert spec.problem.boundary_constraints == [
        "-2*r__0_f + sqrt(r__0(t=0.5)**2 + r__1(t=0.5)**2) - 1 <= 0.0"
    ]


def test_a_radius_at_a_time_meets_the_closed_form() -> None:
    """|r(T/2)|² = 0.25 with r_1(T/2) = 0.3: r_0(T/2) = ±0.4, each axis its closed form."""
    data = _planar(boundary_constraints=["dot(r(t=1), r(t=1)) == 0.25", "r(t=1)[1] == 0.3"])
    data["guess"] = {"states": {"r": "[0.4*sin(pi*tau), 0.3*sin(pi*tau)]"}}
    result = _solve(data)
    assert result.objective == pytest.approx(192 * 0.25 / T**3, rel=1e-9)


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_a_vector_free_event_meets_the_closed_form(backend: str) -> None:
    """The pass through a at a free time: by symmetry at T/2, the fixed-time closed form."""
    event = {"free_event": {"bounds": [0.3, 1.9], "constraints": ["r == [a0, a1]"]}}
    data = _planar() | {"transforms": [event], "method": {"intervals": 6, "degree": 3}}
    assert spec_from_dict(data).transforms[0]["free_event"]["constraints"] == [
        "-a0 + r__0 == 0",
        "-a1 + r__1 == 0",
    ]
    result = _solve(data, backend)
    assert result.metrics["event_time"] == pytest.approx(T / 2, abs=1e-6)
    assert result.objective == pytest.approx(CLOSED_FORM, rel=1e-8)


TABLES = {
    "D": {"axes": [[0, 0.5, 1, 1.5, 2, 3]], "values": [0.1, 0.12, 0.15, 0.2, 0.26, 0.4], "method": "bspline"},
    "W": {"axes": [[-1, 0, 1, 2]], "values": [0.0, 0.1, 0.3, 0.2], "method": "bspline"},
}
"""A drag coefficient of the speed and a cost of the first coordinate."""


def _drag(vector: bool) -> dict:
    """A planar point with drag ``D(|v|) v`` from (0, 0) at speed (1, 0.5) to (1, 1), paying
    ``W(r_0)`` along the way and ``10 W(r_0)`` at the end (a definition at the end)."""
    if vector:
        problem = {
            "tables": TABLES,
            "definitions": {"drag": "D(norm(v))", "h": "W(r[0])"},
            "states": {"r": {"size": 2, "initial": 0, "final": 1}, "v": {"size": 2, "initial": [1, 0.5]}},
            "controls": {"u": {"size": 2}},
            "dynamics": {"r": "v", "v": "u - drag*v"},
            "objective": {"lagrange": "dot(u, u) + h", "mayer": "10*h_f"},
        }
    else:
        problem = {
            "tables": TABLES,
            "definitions": {"drag": "D(sqrt(v0**2 + v1**2))", "h": "W(r0)"},
            "states": {
                "r0": {"initial": 0, "final": 1},
                "r1": {"initial": 0, "final": 1},
                "v0": {"initial": 1},
                "v1": {"initial": 0.5},
            },
            "controls": {"u0": {}, "u1": {}},
            "dynamics": {"r0": "v0", "r1": "v1", "v0": "u0 - drag*v0", "v1": "u1 - drag*v1"},
            "objective": {"lagrange": "u0**2 + u1**2 + h", "mayer": "10*W(r0_f)"},
        }
    problem["time"] = {"final": 1.5}
    return {"kind": "optimal_control", "problem": problem, "method": {"intervals": 12}}


def test_tables_of_a_norm_and_of_a_component_equal_the_scalar_form() -> None:
    spec = spec_from_dict(_drag(vector=True))
    assert spec.problem.definitions == {"drag": "D(sqrt(v__0**2 + v__1**2))", "h": "W(r__0)"}
    assert spec.problem.objective.mayer == "10*W(r__0_f)"
    _same(_solve(_drag(vector=True)), _solve(_drag(vector=False)), POINT)


def test_a_table_from_a_file_is_read_once_with_vectors(tmp_path: Path) -> None:
    """The lowering reads the table's CSV beside the file (the folder of the validation) and hands
    on its numbers."""
    (tmp_path / "w.csv").write_text("-1,0\n0,0.1\n1,0.3\n2,0.2\n")
    data = _drag(vector=True)
    data["problem"]["tables"] = {**TABLES, "W": {"file": "w.csv", "method": "bspline"}}
    import yaml

    (tmp_path / "p.yaml").write_text(yaml.safe_dump({"name": "p", **data}))
    spec = gamespec.load(tmp_path / "p.yaml")
    assert spec.problem.tables["W"].values == TABLES["W"]["values"]
    assert spec.problem.definitions["h"] == "W(r__0)"


def test_a_definition_at_the_end_beside_a_state_at_a_time() -> None:
    """A file without vectors whose Mayer term names ``h_f`` (h a table of x) and whose boundary
    constraint names ``x(t=1)``: the same solve as the definition written out."""
    base = {
        "parameters": {"a": 0.7},
        "tables": {"W": TABLES["W"]},
        "states": {"x": {"initial": 0.0}, "v": {"initial": 0.0, "final": 0.0}},
        "controls": {"u": {}},
        "dynamics": {"x": "v", "v": "u"},
        "time": {"final": T},
        "boundary_constraints": ["x(t=1) + 0*h_0 == a"],
    }
    named = {**base, "definitions": {"h": "W(x)"}, "objective": {"lagrange": "u**2", "mayer": "h_f"}}
    written = {
        **base,
        "objective": {"lagrange": "u**2", "mayer": "W(x_f)"},
        "boundary_constraints": ["x(t=1) == a"],
    }
    one = _solve({"kind": "optimal_control", "problem": named, "method": {"intervals": 10}})
    two = _solve({"kind": "optimal_control", "problem": written, "method": {"intervals": 10}})
    assert one.objective == pytest.approx(two.objective, rel=1e-10)
    np.testing.assert_allclose(one.states["x"], two.states["x"], atol=1e-9)


K, C = 0.8, 1.7
TIMES = [0.2, 0.45, 0.9, 1.3, 2.0, 2.5, 3.0]
NOISE = np.array([0.01, -0.02, 0.015, 0.0, -0.01, 0.02, -0.005])


def _decay(keys: dict[str, str], noise: float) -> tuple[dict, dict]:
    """x' = -k x + c y, y' = -c y as the vector r = (x, y) and as scalars, with the measured keys
    (vector spelling: scalar spelling) of SciPy's solution plus ``noise`` times a fixed pattern."""
    sol = solve_ivp(
        lambda t, z: [-K * z[0] + C * z[1], -C * z[1]],
        (0, 3),
        [1.0, 2.0],
        t_eval=TIMES,
        rtol=1e-12,
        atol=1e-12,
    )
    x, y = sol.y
    exact = {"x": x, "x + y": x + y, "sqrt(x**2 + y**2)": np.hypot(x, y)}
    values = {k: list(exact[s] + noise * NOISE) for k, s in keys.items()}
    design = {"k": {"lower": 0.0, "upper": 5.0, "guess": 1.0}, "c": {"lower": 0.0, "upper": 5.0}}
    method = {"intervals": 30, "degree": 4}
    first = next(iter(keys))
    vector = {
        "design": design,
        "states": {"r": {"size": 2, "initial": [1.0, 2.0]}},
        "dynamics": {"r": "[-k*r[0] + c*r[1], -c*r[1]]"},
        "time": {"final": 3.0},
        "measurements": {"times": TIMES, "values": values, "weights": {first: 0.5}},
    }
    scalar = {
        "design": design,
        "states": {"x": {"initial": 1.0}, "y": {"initial": 2.0}},
        "dynamics": {"x": "-k*x + c*y", "y": "-c*y"},
        "time": {"final": 3.0},
        "measurements": {
            "times": TIMES,
            "values": {keys[k]: v for k, v in values.items()},
            "weights": {keys[first]: 0.5},
        },
    }
    return (
        {"kind": "optimal_control", "problem": vector, "method": method},
        {"kind": "optimal_control", "problem": scalar, "method": method},
    )


KEYS = {"r[0]": "x", "r[0] + r[1]": "x + y", "norm(r)": "sqrt(x**2 + y**2)"}


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_vector_measurements_recover_the_parameters(backend: str) -> None:
    vector, _ = _decay(KEYS, 0.0)
    assert set(spec_from_dict(vector).problem.measurements.values) == {
        "r__0",
        "r__0 + r__1",
        "sqrt(r__0**2 + r__1**2)",
    }
    result = _solve(vector, backend)
    assert result.metrics["design"]["k"] == pytest.approx(K, rel=1e-6)
    assert result.metrics["design"]["c"] == pytest.approx(C, rel=1e-6)
    assert result.objective == pytest.approx(0.0, abs=1e-10)


@pytest.mark.parametrize("backend", ["casadi", "pyomo"])
def test_a_noisy_vector_fit_equals_its_scalar_form(backend: str) -> None:
    vector, scalar = _decay(KEYS, 1.0)
    one, two = _solve(vector, backend), _solve(scalar, backend)
    assert one.objective > 1e-5
    assert one.objective == pytest.approx(two.objective, rel=1e-10)
    assert one.metrics["design"]["k"] == pytest.approx(two.metrics["design"]["k"], rel=1e-8)
    np.testing.assert_allclose(one.states["r__1"], two.states["y"], atol=1e-8)


@pytest.mark.parametrize(
    ("change", "field", "reason"),
    [
        (
            {"measurements": {"times": [1.0], "values": {"r": [0.1]}}},
            "problem.measurements.values.r",
            "measure a vector's components",
        ),
        (
            {"measurements": {"times": [1.0], "values": {"r[0]": [0.1], "r[-2]": [0.2]}}},
            "problem.measurements.values",
            "measure one expression",
        ),
        ({"objective": {"lagrange": "W(r)"}}, "problem.objective.lagrange", "W takes scalars"),
        (
            {"boundary_constraints": ["u(t=1) == [0, 0]"]},
            "problem.boundary_constraints.0",
            "only for a state",
        ),
        (
            {"at": [{"time": 1.0, "constraints": ["u == [0, 0]"]}]},
            "problem.at.0.constraints.0",
            "undefined symbol 'u'",
        ),
    ],
)
def test_what_stays_refused_names_its_field(change: dict, field: str, reason: str) -> None:
    data = _planar(tables={"W": TABLES["W"]}, **change)
    with pytest.raises(SpecError, match=reason) as err:
        spec_from_dict(data)
    assert err.value.field == field


def test_a_scalar_file_with_points_and_tables_is_read_as_written() -> None:
    data = _planar_scalar(**SCALAR_AT, tables={"W": TABLES["W"]}, path_constraints=["W(r0) <= 1/1"])
    spec = spec_from_dict(data)
    assert spec.problem.at[0].constraints == ["r0 == a0", "r1 == a1"]
    assert spec.problem.path_constraints == ["W(r0) <= 1/1"]


def _two_phases(vector: bool) -> dict:
    """Two phases of a planar point paying ``W(r_0)``, linked through a table of the second
    phase's start; the first phase measures ``|r|`` (vector) or its written-out form (scalar)."""
    if vector:
        problem = {
            "states": {"r": {"size": 2, "initial": 0, "final": [1, 0.5]}},
            "controls": {"u": {"size": 2}},
            "dynamics": {"r": "u"},
            "objective": {"lagrange": "dot(u, u) + W(r[0])"},
            "boundary_constraints": ["W(phases.b.r_0[0]) >= 0.2"],
        }
        key = "norm(r)"
    else:
        problem = {
            "states": {"r0": {"initial": 0, "final": 1}, "r1": {"initial": 0, "final": 0.5}},
            "controls": {"u0": {}, "u1": {}},
            "dynamics": {"r0": "u0", "r1": "u1"},
            "objective": {"lagrange": "u0**2 + u1**2 + W(r0)"},
            "boundary_constraints": ["W(phases.b.r0_0) >= 0.2"],
        }
        key = "sqrt(r0**2 + r1**2)"
    measured = {"times": [0.5], "values": {key: [0.3]}}
    problem |= {
        "tables": {"W": TABLES["W"]},
        "phases": [
            {"name": "a", "duration": 1.0, "measurements": measured},
            {"name": "b", "duration": 1.0},
        ],
    }
    return {"kind": "multiphase_optimal_control", "problem": problem, "method": {"intervals": 6}}


def test_vector_phases_with_a_table_and_measurements_equal_the_scalar_form() -> None:
    spec = spec_from_dict(_two_phases(vector=True))
    assert spec.problem.boundary_constraints == ["W(phases.b.r__0_0) - 0.2 >= 0.0"]
    assert list(spec.problem.phases[0].measurements.values) == ["sqrt(r__0**2 + r__1**2)"]
    one, two = _solve(_two_phases(vector=True)), _solve(_two_phases(vector=False))
    _same(one, two, {"r__0": "r0", "r__1": "r1"})


def test_a_state_at_a_time_prints_as_the_grammar_spells_it() -> None:
    """The printer writes ``x(t=5.0)`` back as it is read; a name that only looks like one is
    refused."""
    from gamespec.errors import ExpressionError
    from gamespec.symbolic.language import symbol
    from gamespec.symbolic.printer import to_text

    assert to_text(2 * symbol("x(t=5.0)") + 1) == "2*x(t=5.0) + 1"
    for name in ("x(t=5)", "phases.a.x(t=1.0)", "x(t=y)"):
        with pytest.raises(ExpressionError, match="cannot be written"):
            to_text(symbol(name))
