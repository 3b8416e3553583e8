"""The whitelist walk without SymPy (:mod:`gamespec.symbolic.grammar`) against the walk into SymPy
(:mod:`gamespec.symbolic.language`): the same texts refused, the same values built (straight from
the text with NumPy, or SymPy translated to NumPy), and every shipped ``optimal_control`` file's
terms equal on both routes, so that a CasADi or Pyomo model built from the text is the model the
SymPy form describes."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
import yaml
from hypothesis import HealthCheck, assume, given, settings

import gamespec
from gamespec.errors import ExpressionError
from gamespec.loader import load, spec_from_dict
from gamespec.ocp.checks import hamiltonian_end_value
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.ocp.transcription import Transcription
from gamespec.symbolic.canonical import check
from gamespec.symbolic.grammar import FLOATS, dependencies, expression, numeric_value, relation, unknowns
from gamespec.symbolic.language import SYMPY, parse, parse_relation, symbol
from gamespec.symbolic.library import NUMPY, LibraryAlgebra
from gamespec.symbolic.printer import to_text
from gamespec.symbolic.translate import numeric, translate
from tests.conftest import PROBLEMS
from tests.core.test_printer import MORE_BINARY, MORE_UNARY, REAL_BINARY, REAL_UNARY, representable, trees

ARRAYS = LibraryAlgebra(NUMPY)
NAMES_XYT = ("x", "y", "t")
RNG_POINTS = np.random.default_rng(7).uniform(-2.0, 2.0, size=(3, 16))
ZERMELO = PROBLEMS / "ch6" / "zermelo_min_time.yaml"


@pytest.mark.parametrize(
    "text",
    [
        "1/0",
        "x/0",
        "x/(1 - 1)",
        "log(0)",
        "sqrt(-1)",
        "(-2)**0.5",
        "9**9**9",
        "exp(1000) - exp(1000)",
        "x*1e300*1e300",
        "x/1e-300/1e-300",
        "(x*1e300)**2",
        "max(exp(exp(exp(9))), x)",
        "sin(10**400)",
        "1e400",
        "x^2",
        "z",
        "sin",
        "f(x)",
        "x < 1",
        "[x]",
        "1/(x - x)",
        "x/(x*y - y*x)",
        "log(x + (-x))",
        "sqrt(t - t - 1)",
        "log(0*x)",
        "exp(log(0*x))",
        "atan2(0, 0)",
        "atan2(y - y, 0)",
    ],
)
def test_both_walks_refuse_the_same_texts(text: str) -> None:
    with pytest.raises(ExpressionError):
        parse(text, {n: symbol(n) for n in NAMES_XYT})
    with pytest.raises(ExpressionError):
        check(text, NAMES_XYT)


@pytest.mark.parametrize(
    "text",
    [
        "x*1e300/1e300",
        "1e300*x + 1e300*y",
        "exp(x*1e300)",
        "2**1000*x",
        "atan2(0, -1)",
        "heaviside(0)*x",
        "exp(log(x))",
        "x - x + 1",
        "1/(x - y)",
        "log(x/x)",
        "+".join(["x"] * 400),
        "-" * 300 + "x",
    ],
    ids=lambda text: text if len(text) < 40 else f"{text[:20]}...({len(text)} characters)",
)
def test_both_walks_accept_the_same_texts(text: str) -> None:
    parse(text, {n: symbol(n) for n in NAMES_XYT})
    check(text, NAMES_XYT)


@pytest.mark.parametrize(
    "text", ["2*pi/3 + atan2(1, 2)", "sqrt(2)**2 - heaviside(0)", "min(3, 2**-1) * sign(-4)"]
)
def test_numbers_agree_with_sympy(text: str) -> None:
    assert numeric_value(text, {}) == pytest.approx(numeric(parse(text, {}), {}), rel=1e-15, abs=1e-15)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(trees(REAL_UNARY + MORE_UNARY, REAL_BINARY + MORE_BINARY))
def test_building_from_the_text_equals_translating_its_sympy(expr: sp.Expr) -> None:
    """Two routes from one text to NumPy values: the grammar's walk with NumPy's library, and
    SymPy (with its simplifications) translated to NumPy; they agree wherever both are finite.
    Numbers beyond 1e6 are left out: ``sin(8615125/(y**2 + 1)**3)`` is exact on both routes up
    to a rounding of its argument that the sine turns into 2e-9 (its conditioning, not a fault)."""
    assume(representable(expr))
    assume(all(abs(n) <= 1e6 for n in expr.atoms(sp.Number)))
    text = to_text(expr)
    symbols = {n: symbol(n) for n in NAMES_XYT}
    try:
        parsed = parse(text, symbols)
        with np.errstate(all="ignore"):
            direct = expression(text, dict(zip(NAMES_XYT, RNG_POINTS, strict=True)), ARRAYS)
    except ExpressionError:
        return  # refused by a walk: the cases above hold those side by side
    with np.errstate(all="ignore"):
        via_sympy = translate(parsed, dict(zip(symbols.values(), RNG_POINTS, strict=True)), NUMPY)
        a, b = (np.broadcast_to(np.asarray(v, dtype=float), (16,)) for v in (direct, via_sympy))
    both = np.isfinite(a) & np.isfinite(b) & (np.abs(b) < 1e12)
    np.testing.assert_allclose(a[both], b[both], rtol=1e-9, atol=1e-9)
    names = dependencies(expression(text, unknowns(NAMES_XYT), FLOATS))
    assert names >= {str(s) for s in parsed.free_symbols}


def test_relations_carry_the_same_bounds() -> None:
    for text in ("x <= 2*y", "x >= 1", "x == y", "-1 <= x + y <= 2", "2 >= x >= -pi"):
        names = relation(text, unknowns(NAMES_XYT), FLOATS)
        from_sympy = parse_relation(text, {n: symbol(n) for n in NAMES_XYT})
        assert (names.lower, names.upper) == (from_sympy.lower, from_sympy.upper)
        assert dependencies(names.expr) == {str(s) for s in from_sympy.expr.free_symbols}


OCP_FILES = sorted(p for p in PROBLEMS.rglob("*.yaml") if "kind: optimal_control" in p.read_text())


@pytest.mark.parametrize("path", OCP_FILES, ids=lambda p: str(p.relative_to(PROBLEMS)))
def test_shipped_files_build_the_same_terms_on_both_routes(path) -> None:
    """Each running and end term of each shipped ``optimal_control`` file, built from the text over
    NumPy arrays (what CasADi, Pyomo and the checks use) and built in SymPy then translated to
    NumPy (what the transforms differentiate), at random points."""
    ocp = SymbolicOcp(load(path))
    rng = np.random.default_rng(3)
    params = ocp.parameter_values()
    others = params | {n: 0.5 for n in ocp.design}
    running = {n: rng.uniform(0.1, 1.5, 8) for n in ocp.running_names} | others
    ends = {n: float(rng.uniform(0.1, 1.5)) for n in ocp.end_names} | others
    symbols = {n: symbol(n) for n in [*ocp.running_names, *ocp.end_names]}
    sym_running = ocp.running_terms({n: symbols[n] for n in ocp.running_names}, SYMPY)
    sym_ends = ocp.end_terms({n: symbols[n] for n in ocp.end_names}, SYMPY)
    with np.errstate(all="ignore"):
        direct = ocp.running_terms(running, ARRAYS)
        direct_ends = ocp.end_terms(ends, ARRAYS)
        pairs = [
            *zip(direct.dynamics, sym_running.dynamics, strict=True),
            (direct.lagrange, sym_running.lagrange),
            *((a.expr, b.expr) for a, b in zip(direct.path, sym_running.path, strict=True)),
            *zip(direct.integrands, sym_running.integrands, strict=True),
        ]
        values = {symbols[n]: v for n, v in running.items()}
        for built, sympy_form in pairs:
            expected = np.asarray(translate(sympy_form, values, NUMPY), dtype=float)
            np.testing.assert_allclose(*np.broadcast_arrays(built, expected), rtol=1e-10, atol=1e-12)
        end_pairs = [(direct_ends.mayer, sym_ends.mayer)]
        end_pairs += [(a.expr, b.expr) for a, b in zip(direct_ends.boundary, sym_ends.boundary, strict=True)]
        values = {symbols[n]: v for n, v in ends.items()}
        for built, sympy_form in end_pairs:
            expected = float(translate(sympy_form, values, NUMPY))
            assert float(built) == pytest.approx(expected, rel=1e-10, abs=1e-12)
    structure = ocp.end_terms(unknowns(ocp.end_names), FLOATS)
    bounds = [(r.lower, r.upper) for r in ocp.running_structure.path + structure.boundary]
    assert bounds == [(r.lower, r.upper) for r in sym_running.path + sym_ends.boundary]


def test_autonomy_and_inputs_follow_the_definitions() -> None:
    """``t`` and a grid input reached only through a definition count as used, as in SymPy's
    substituted form; a chained path constraint keeps its numeric bounds."""
    data = yaml.safe_load(ZERMELO.read_text())
    problem = data["problem"]
    problem["inputs"] = {"gust": {"default": 0.0}, "unused": {"default": 1.0}}
    problem["definitions"] = {"clock": "t", "push": "gust*clock"}
    problem["dynamics"] = {"x1": "cos(u) + rho*x2", "x2": "sin(u) + push"}
    problem["path_constraints"] = ["-1 <= x2 + 0*clock <= 0.5", "x1 >= -pi"]
    ocp = SymbolicOcp(spec_from_dict(data, source="test"))
    assert [(r.lower, r.upper) for r in ocp.running_structure.path] == [(-1.0, 0.5), (0.0, math.inf)]
    assert [(r.lower, r.upper) for r in ocp.path] == [(-1.0, 0.5), (0.0, math.inf)]
    sympy_free = set().union(*(e.free_symbols for e in [*ocp.dynamics, ocp.lagrange]))
    assert not ocp.autonomous and symbol("t") in sympy_free
    assert ocp.inputs_in_hamiltonian == [0]
    assert [i for i, s in enumerate(ocp.w) if s in sympy_free] == [0]


def test_hamiltonian_end_value_is_minus_the_mayer_slope_in_t_f() -> None:
    """The central difference of the checks against SymPy's exact ``-dPhi/dt_f`` for a Mayer term
    nonlinear in ``t_f`` (eq. 2.23's transversality value)."""
    data = yaml.safe_load(ZERMELO.read_text())
    data["problem"]["objective"]["mayer"] = "t_f**2 + 3*sin(t_f)*x1_f"
    tr = Transcription(spec_from_dict(data, source="test"))
    ends = tr.ocp.end_values(([0.0, 0.0], [0.7, 0.2]), ([0.1], [0.3]), 1.3, tr.ocp.parameter_values())
    exact = -sp.diff(tr.ocp.mayer, symbol("t_f"))
    expected = float(translate(exact, {symbol(n): v for n, v in ends.items()}, NUMPY))
    assert hamiltonian_end_value(tr, ends) == pytest.approx(expected, rel=1e-8)
    assert not math.isclose(expected, -1.0)


def test_checks_of_a_failed_solve_evaluate_to_nan_not_an_error() -> None:
    """A solve that stops at ``log(x1_f)`` with ``x1_f = 0`` (the guess) is a Result with its
    status (exit 1), not an expression error (exit 2): its checks are NaN where a term is not a
    number, as NumPy computes them."""
    data = yaml.safe_load(ZERMELO.read_text())
    problem = data["problem"]
    problem["states"]["x1"] = {"initial": 0.0}
    problem["objective"]["mayer"] = "t_f - log(x1_f)"
    problem["boundary_constraints"] = ["x1_f >= 0.5"]
    data["solver"] = {"options": {"casadi": {"max_iter": 3}}}
    result = gamespec.solve(spec_from_dict(data, source="test"), "casadi")
    assert result.status.value != "optimal"
    assert math.isnan(result.checks["hamiltonian_end_error"])


@pytest.mark.parametrize("text", ["(-0.0 / -0.0)", "0.0/0.0", "1/(-0.0)"])
def test_a_quotient_by_a_zero_float_is_refused_in_sympy_as_in_floats(text):
    """SymPy's floats divide a zero by a zero as mpmath does, raising ZeroDivisionError (found by
    the long solve-path fuzz in a flow-field drift); both walks refuse it with one message."""
    messages = []
    for algebra in (FLOATS, SYMPY):
        with pytest.raises(ExpressionError) as refused:
            expression(text, {}, algebra)
        messages.append(str(refused.value))
    assert messages[0] == messages[1] and "undefined" in messages[0]
