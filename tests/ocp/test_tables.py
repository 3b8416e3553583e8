"""The ``tables:`` section (issue 25, item 1): one interpolant on every route (CasADi, SciPy, the
load-time check), derivatives that agree with finite differences, an interpolant of a known function
reproducing the analytic problem's optimum, and bad tables refused at load with one line."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import gamespec
import gamespec.reading
from gamespec.errors import SpecError, UnsupportedFeature
from gamespec.loader import spec_from_dict
from gamespec.specs.tables import checked_table
from tests.conftest import PROBLEMS

LQ_T = 1.0


def _lq(cost: str, tables: dict | None = None) -> dict:
    """min integral of q(x) + u^2 with x' = u, x(0) = 1 on [0, 1]: with q = x^2 the scalar Riccati
    equation P' = P^2 - 1, P(1) = 0 gives P(t) = tanh(1 - t) and J* = tanh(1) x(0)^2."""
    return {
        "kind": "optimal_control",
        "problem": {
            "tables": tables or {},
            "states": {"x": {"initial": 1.0}},
            "controls": {"u": {}},
            "dynamics": {"x": "u"},
            "objective": {"lagrange": cost},
            "time": {"final": LQ_T},
        },
        "method": {"intervals": 20, "degree": 4},
    }


def _square(method: str, points: int) -> dict:
    grid = np.linspace(-2.0, 2.0, points)
    return {"q": {"axes": [grid.tolist()], "values": (grid**2).tolist(), "method": method}}


def test_bspline_table_of_a_quadratic_reproduces_the_riccati_optimum() -> None:
    """A cubic spline reproduces x^2 exactly, so the optimum is the analytic one, tanh(1)."""
    analytic = gamespec.solve(spec_from_dict(_lq("x**2 + u**2")))
    tabulated = gamespec.solve(spec_from_dict(_lq("q(x) + u**2", _square("bspline", 9))))
    assert tabulated.status == gamespec.Status.OPTIMAL, tabulated.message
    assert all(tabulated.metrics["checks_passed"].values())
    assert tabulated.objective == pytest.approx(math.tanh(LQ_T), rel=1e-8)
    assert tabulated.objective == pytest.approx(analytic.objective, rel=1e-10)


def test_linear_table_on_a_fine_grid_converges_to_the_riccati_optimum() -> None:
    """Multilinear interpolation of x^2 overestimates it by at most h^2/4: the optimum moves by
    O(h^2)."""
    errors = []
    for points in (41, 161):
        result = gamespec.solve(spec_from_dict(_lq("q(x) + u**2", _square("linear", points))))
        assert result.status == gamespec.Status.OPTIMAL, result.message
        errors.append(abs(result.objective - math.tanh(LQ_T)))
    h = 4.0 / 40
    assert errors[0] < h**2
    assert errors[1] < errors[0] / 8


@pytest.mark.parametrize("method", ["linear", "bspline"])
def test_casadi_and_scipy_evaluate_the_same_table(method: str) -> None:
    """The CasADi interpolant and the SciPy route agree inside and outside the grid (3 axes), and
    CasADi's gradient agrees with central differences of the SciPy route."""
    ca = pytest.importorskip("casadi")
    rng = np.random.default_rng(3)
    axes = [np.sort(rng.uniform(0, 4, 6)), np.linspace(-1, 1, 5), np.array([0.0, 0.5, 2.0, 3.0])]
    values = rng.normal(size=(6, 5, 4))
    table = checked_table("g", [a.tolist() for a in axes], values.tolist(), method)
    points = rng.uniform([-0.5, -1.5, -0.5], [4.5, 1.5, 3.5], size=(50, 3))
    x = ca.SX.sym("x", 3)
    value = table.casadi(*ca.vertsplit(x))
    fn = ca.Function("g", [x], [value, ca.gradient(value, x)])
    scipy_values = table.numpy(*points.T)
    h = 1e-6
    for point, expected in zip(points, scipy_values, strict=True):
        v, grad = fn(point)
        assert float(v) == pytest.approx(expected, abs=1e-10)
        assert table.floats(*point) == pytest.approx(expected, abs=1e-12)
        for i in range(3):
            step = np.eye(3)[i] * h
            slope = (table.floats(*(point + step)) - table.floats(*(point - step))) / (2 * h)
            assert float(grad[i]) == pytest.approx(slope, abs=1e-5)


def test_bspline_hessian_is_the_spline_second_derivative() -> None:
    """For bspline the Hessian comes with the interpolant: a table of sin gives -sin to the
    spline's accuracy."""
    ca = pytest.importorskip("casadi")
    grid = np.linspace(0.0, 3.0, 61)
    table = checked_table("s", [grid.tolist()], np.sin(grid).tolist(), "bspline")
    x = ca.SX.sym("x")
    second = ca.Function("d2", [x], [ca.hessian(table.casadi(x), x)[0]])
    for at in (0.4, 1.3, 2.2):
        assert float(second(at)) == pytest.approx(-math.sin(at), abs=1e-3)


def test_akima_table_of_a_quadratic_reproduces_the_riccati_optimum() -> None:
    """Akima's slopes are exact for a quadratic on an even grid (equal weights average the two
    neighbouring secants; its end extrapolation continues the secants linearly), so the table of
    x^2 is x^2 and the optimum is tanh(1)."""
    tabulated = gamespec.solve(spec_from_dict(_lq("q(x) + u**2", _square("akima", 9))))
    assert tabulated.status == gamespec.Status.OPTIMAL, tabulated.message
    assert all(tabulated.metrics["checks_passed"].values())
    assert tabulated.objective == pytest.approx(math.tanh(LQ_T), rel=1e-8)


def test_akima_table_is_scipys_akima_with_its_derivatives_on_casadi() -> None:
    """On an uneven grid of uneven data, CasADi's B-spline form of the Akima table equals SciPy's
    Akima1DInterpolator (inside; clamped outside), its gradient equals central differences of the
    SciPy route and its Hessian SciPy's second derivative."""
    ca = pytest.importorskip("casadi")
    from scipy.interpolate import Akima1DInterpolator

    rng = np.random.default_rng(7)
    grid = np.sort(rng.uniform(0.0, 6.0, 12))
    data = np.sin(grid) + rng.normal(scale=0.2, size=grid.size)
    table = checked_table("a", [grid.tolist()], data.tolist(), "akima")
    reference = Akima1DInterpolator(grid, data)
    x = ca.SX.sym("x")
    value = table.casadi(x)
    fn = ca.Function("a", [x], [value, ca.gradient(value, x), ca.hessian(value, x)[0]])
    h = 1e-6
    inside = rng.uniform(grid[0], grid[-1], 40)
    assert np.allclose(table.numpy(inside), reference(inside), rtol=0, atol=1e-13)
    for at in inside:
        v, grad, second = (float(part) for part in fn(at))
        assert v == pytest.approx(float(reference(at)), abs=1e-12)
        slope = (table.floats(at + h) - table.floats(at - h)) / (2 * h)
        assert grad == pytest.approx(slope, abs=1e-6)
        assert second == pytest.approx(float(reference.derivative(2)(at)), abs=1e-8)
    for beyond, edge in ((grid[0] - 1.0, data[0]), (grid[-1] + 1.0, data[-1])):
        assert float(fn(beyond)[0]) == pytest.approx(edge, abs=1e-12)
        assert table.floats(beyond) == pytest.approx(edge, abs=1e-12)


def test_akima_table_of_two_axes_is_refused() -> None:
    with pytest.raises(ValueError, match="akima takes a table of one axis"):
        checked_table("a", [[0.0, 1.0, 2.0], [0.0, 1.0, 2.0]], np.zeros((3, 3)).tolist(), "akima")


def test_table_csv_and_npz_files_are_read_next_to_the_problem_file(tmp_path: Path) -> None:
    grid = np.linspace(-2.0, 2.0, 9)
    (tmp_path / "q.csv").write_text("x,q\n" + "".join(f"{g},{g * g}\n" for g in grid))
    np.savez(tmp_path / "q.npz", values=grid**2, axis0=grid)
    results = []
    for file in ("q.csv", "q.npz"):
        data = _lq("q(x) + u**2", {"q": {"file": file, "method": "bspline"}})
        problem = tmp_path / f"lq_{file.replace('.', '_')}.json"
        problem.write_text(__import__("json").dumps(data))
        results.append(gamespec.solve(gamespec.load(problem)))
    assert results[0].objective == pytest.approx(math.tanh(LQ_T), rel=1e-8)
    assert results[1].objective == pytest.approx(results[0].objective, rel=1e-12)


def test_two_axis_csv_grid(tmp_path: Path) -> None:
    (tmp_path / "g.csv").write_text("x\\y,0,1,2\n0,0,1,2\n1,1,2,3\n")
    import json

    data = _lq("u**2 + g(x, 0.5)", {"g": {"file": "g.csv"}})
    problem = tmp_path / "p.json"
    problem.write_text(json.dumps(data))
    spec = gamespec.load(problem)
    assert spec.problem.functions["g"].floats(0.5, 0.5) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("table", "reason"),
    [
        ({"axes": [[0, 1, 1]], "values": [0, 1, 2]}, "strictly increasing"),
        ({"axes": [[0, 1, 2]], "values": [0, 1]}, "shape"),
        ({"axes": [[0, 1, 2]], "values": [0, 1, 2], "method": "bspline"}, "at least 4"),
        ({"file": "../outside.csv"}, "inside the problem file's folder"),
        ({"file": "missing.csv"}, "not found"),
        ({"file": "-" * 300 + ".csv"}, "File name too long"),
    ],
)
def test_bad_tables_are_refused_at_load(table: dict, reason: str) -> None:
    with pytest.raises(SpecError, match=reason):
        spec_from_dict(_lq("q(x) + u**2", {"q": table}))


def test_table_calls_are_checked_by_the_grammar() -> None:
    tables = _square("linear", 5)
    with pytest.raises(SpecError, match="takes 1 argument"):
        spec_from_dict(_lq("q(x, u) + u**2", tables))
    with pytest.raises(SpecError, match="used without arguments"):
        spec_from_dict(_lq("q + u**2", tables))
    with pytest.raises(SpecError, match="names used twice"):
        spec_from_dict(_lq("u**2", {"x": tables["q"]}))


@pytest.mark.parametrize(
    ("method", "axes"),
    [("linear", 3), ("bspline", 3), ("bspline", 2), ("linear", 1), ("bspline", 1), ("akima", 1)],
)
def test_pyomo_form_of_a_table_is_the_scipy_table(method: str, axes: int) -> None:
    """The Pyomo expression of a table (arithmetic and abs, :mod:`gamespec.symbolic.truncated`),
    evaluated by Pyomo at fixed Vars, equals the SciPy route inside and beyond the grid."""
    pyo = pytest.importorskip("pyomo.environ")
    rng = np.random.default_rng(3)
    grids = [np.sort(rng.uniform(0, 4, 6)), np.linspace(-1, 1, 5), np.array([0.0, 0.5, 2.0, 3.0])][:axes]
    if method == "akima":
        grids = [np.sort(rng.uniform(0, 4, 8))]
    values = rng.normal(size=tuple(len(g) for g in grids))
    table = checked_table("g", [g.tolist() for g in grids], values.tolist(), method)
    model = pyo.ConcreteModel()
    model.x = pyo.Var(range(len(grids)))
    expr = table.truncated(*(model.x[i] for i in range(len(grids))))
    points = rng.uniform([g[0] - 0.5 for g in grids], [g[-1] + 0.5 for g in grids], size=(100, len(grids)))
    for point in points:
        for i, value in enumerate(point):
            model.x[i].value = float(value)
        assert pyo.value(expr) == pytest.approx(table.floats(*point), abs=1e-10)


@pytest.mark.parametrize(("method", "points"), [("bspline", 9), ("akima", 9), ("linear", 41)])
def test_a_table_solves_the_same_on_pyomo_as_on_casadi(method: str, points: int) -> None:
    """The tabulated LQ problem on both backends: the same optimum (tanh(1) where the table is
    x^2 exactly; the linear table's O(h^2) offset alike on both)."""
    spec = spec_from_dict(_lq("q(x) + u**2", _square(method, points)))
    on_casadi, on_pyomo = (gamespec.solve(spec, backend=b) for b in ("casadi", "pyomo"))
    assert on_pyomo.status == gamespec.Status.OPTIMAL, on_pyomo.message
    assert all(on_pyomo.metrics["checks_passed"].values())
    assert on_pyomo.objective == pytest.approx(on_casadi.objective, rel=1e-9)
    if method != "linear":
        assert on_pyomo.objective == pytest.approx(math.tanh(LQ_T), rel=1e-8)


def test_pyomo_refuses_a_table_whose_form_would_round_beyond_the_tolerance() -> None:
    """Grid intervals of very different sizes make the truncated powers cancel: measured, and
    refused naming the table."""
    grid = np.concatenate([np.linspace(0.0, 1e-4, 5), np.linspace(1.0, 1e4, 20)])
    tables = {"q": {"axes": [grid.tolist()], "values": np.sin(grid).tolist(), "method": "bspline"}}
    spec = spec_from_dict(_lq("q(x) + u**2", tables))
    with pytest.raises(UnsupportedFeature, match="cannot take table 'q'"):
        gamespec.solve(spec, backend="pyomo")


def test_a_table_in_sympy_prints_back_and_its_derivative_is_refused_by_the_printer() -> None:
    import sympy as sp

    from gamespec.errors import ExpressionError
    from gamespec.symbolic.canonical import check
    from gamespec.symbolic.language import parse, symbol
    from gamespec.symbolic.printer import to_text

    q = checked_table("q", [[0, 1, 2, 3]], [0, 1, 4, 9], "bspline")
    names = {"x": symbol("x"), "q": q}
    expr = parse("q(x)*x + sqrt(q(x) + 1)", names)
    assert parse(to_text(expr), names) == expr
    assert parse("q(2)", names) == pytest.approx(4.0)
    with pytest.raises(ExpressionError, match="derivative of table 'q'"):
        to_text(sp.diff(expr, symbol("x")))
    check("1/(q(x) + 1) + sqrt(q(x))", ["x"], functions={"q": q})


def test_f4_minimum_time_to_climb_solves_with_its_published_tables() -> None:
    """The F-4 climb (thrust table from a CSV grid, atmosphere from 1-D CSV tables): optimal, every
    check passing, Mach 1 in level flight at 20 km (the published time is compared in the file's
    header, not here)."""
    result = gamespec.solve(PROBLEMS / "ocp" / "f4_min_time_climb.yaml")
    assert result.status == gamespec.Status.OPTIMAL, result.message
    assert all(result.metrics["checks_passed"].values())
    spec = gamespec.load(PROBLEMS / "ocp" / "f4_min_time_climb.yaml")
    sos = spec.problem.functions["sos"]
    assert result.states["v"][-1] == pytest.approx(sos.floats(result.states["h"][-1]), rel=1e-8)


def test_tables_pass_through_the_multiphase_lowering() -> None:
    """The two-phase minimum-time double integrator with its unit accelerations read from a table:
    the closed form t_f = 2 sqrt(x0) holds as with the numbers written in."""
    data = gamespec.reading.read_file(PROBLEMS / "ocp" / "double_integrator_two_phases.yaml")
    data["problem"]["tables"] = {"gain": {"axes": [[-10.0, 0.0, 10.0]], "values": [1.0, 1.0, 1.0]}}
    data["problem"]["phases"][0]["dynamics"] = {"v": "-gain(x)"}
    data["problem"]["phases"][1]["dynamics"] = {"v": "gain(v)"}
    result = gamespec.solve(spec_from_dict(data))
    assert result.status == gamespec.Status.OPTIMAL, result.message
    x0 = data["problem"]["parameters"]["x0"]
    assert result.t_final == pytest.approx(2 * math.sqrt(x0), rel=1e-8)


def test_three_axis_npz_table_is_read_and_evaluated_as_written(tmp_path: Path) -> None:
    """A table of x + 2y + 3z on a 3-axis grid from an NPZ file: multilinear interpolation
    reproduces the linear function everywhere (and beyond the grid, extended linearly)."""
    import json

    axes = [np.linspace(0, 1, 3), np.linspace(-1, 1, 4), np.array([0.0, 2.0])]
    grid = np.meshgrid(*axes, indexing="ij")
    np.savez(
        tmp_path / "g.npz",
        values=grid[0] + 2 * grid[1] + 3 * grid[2],
        axis0=axes[0],
        axis1=axes[1],
        axis2=axes[2],
    )
    problem = tmp_path / "p.json"
    problem.write_text(json.dumps(_lq("u**2 + g(x, u, 1)", {"g": {"file": "g.npz"}})))
    g = gamespec.load(problem).problem.functions["g"]
    for point in ([0.3, 0.2, 1.0], [1.5, -2.0, 3.0]):
        assert g.floats(*point) == pytest.approx(point[0] + 2 * point[1] + 3 * point[2], abs=1e-12)
