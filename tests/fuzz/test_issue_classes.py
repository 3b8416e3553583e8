"""One regression case per class of bad input found by the mutation fuzz of issue 15: each returns
exit 2 with one line naming the file (or ``--set``), the field or line, and the reason (or, for a
failed solve, exit 1 with its status), within a second of CPU time once gamespec is imported."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml

from gamespec.limits import MAX_INT_DIGITS, MAX_VALUES
from tests.conftest import PROBLEMS
from tests.fuzz.harness import Outcome, assert_promise, run_cli

ZERMELO = PROBLEMS / "ch6" / "zermelo_min_time.yaml"
LQ = PROBLEMS / "ch4" / "test_example.yaml"
SCENARIO = PROBLEMS / "ch3" / "mpse_five_on_one_pp.yaml"
ENGAGEMENT = PROBLEMS / "ch2" / "pure_pursuit_two_on_one.yaml"
ONE_SECOND = 1.0


@pytest.fixture(scope="module", autouse=True)
def _imported() -> None:
    """Import everything a validate of each kind needs once, so the cases time gamespec, not imports."""
    for path in (ZERMELO, LQ, SCENARIO, ENGAGEMENT):
        assert run_cli(["validate", path]).code == 0


def _refused(args: list[object], *needles: str, source: str | None = None) -> Outcome:
    """Exit 2, one line from the file (or ``source``) holding every needle, within a second of CPU
    time."""
    outcome = run_cli([str(a) for a in args], bound_s=10 * ONE_SECOND)
    target = source or str(args[1])
    assert_promise(outcome, target)
    assert outcome.code == 2, outcome
    for needle in needles:
        assert needle in outcome.err, (needle, outcome.err)
    assert outcome.seconds < ONE_SECOND, outcome
    return outcome


def _yaml(tmp_path: Path, data: dict, name: str = "p.yaml") -> Path:
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def _text(tmp_path: Path, text: str | bytes, name: str) -> Path:
    path = tmp_path / name
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(text)
    return path


def _load(path: Path) -> dict:
    return yaml.safe_load(path.read_text())


# Hangs


def test_exact_evaluation_of_a_huge_expression(tmp_path) -> None:
    data = _load(LQ)
    data["problem"]["initial"]["covariance"] = {"diag": ["exp(exp(exp(100)))", 0.05, 0.01, 0.01]}
    _refused(["validate", _yaml(tmp_path, data)], "covariance.diag.0", "out of range")


def test_a_parameter_that_makes_an_expression_huge(tmp_path) -> None:
    data = _load(LQ)
    data["problem"]["parameters"]["dt"] = 100.0
    data["problem"]["discrete"]["A"][0][0] = "exp(exp(exp(dt)))"
    _refused(["validate", _yaml(tmp_path, data)], "discrete.A.0.0", "out of range")


def test_billion_laughs(tmp_path) -> None:
    lines = ["kind: optimal_control", "a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 10)]
    path = _text(tmp_path, "\n".join(lines) + "\n", "laughs.yaml")
    assert path.stat().st_size < 2048
    _refused(["validate", path], f"more than {MAX_VALUES} values", "line ")


# Tracebacks at load


@pytest.mark.parametrize(("key", "hint"), [("x-notes", "valid:"), ("capture-radius", "'capture_radius'")])
def test_unknown_key_with_a_dash(tmp_path, key, hint) -> None:
    data = _load(ENGAGEMENT) | {key: 1}
    _refused(["validate", _yaml(tmp_path, data)], f"{key}: unknown key {key!r}", hint)


def test_dash_key_nested_in_a_list(tmp_path) -> None:
    data = _load(ENGAGEMENT)
    data["pursuers"][1]["max-speed"] = 2
    _refused(["validate", _yaml(tmp_path, data)], "pursuers.1.max-speed", "unknown key")


def test_set_with_brackets_is_one_line() -> None:
    outcome = run_cli(["validate", ENGAGEMENT, "--set", "pursuers[1].speed=1.6"])
    assert_promise(outcome, str(ENGAGEMENT), "--set")
    assert outcome.code in (0, 2)


def test_a_file_that_is_not_utf8(tmp_path) -> None:
    path = _text(tmp_path, b"kind: optimal_control\nname: \xff\xfe\n", "latin.yaml")
    _refused(["validate", path], "not UTF-8", "line 2, column 7")


@pytest.mark.parametrize(
    ("suffix", "template"),
    [
        (".json", '{{"kind": "optimal_control", "x": {}}}'),
        (".yaml", "kind: optimal_control\nx: {}\n"),
        (".toml", 'kind = "optimal_control"\nx = {}\n'),
    ],
)
def test_integer_literal_beyond_pythons_limit(tmp_path, suffix, template) -> None:
    path = _text(tmp_path, template.format("9" * (MAX_INT_DIGITS + 1)), f"digits{suffix}")
    _refused(["validate", path], f"longer than {MAX_INT_DIGITS} digits", "line ")


@pytest.mark.parametrize(
    ("suffix", "template"),
    [
        (".json", '{{"kind": "optimal_control", "x": {}}}'),
        (".yaml", "kind: optimal_control\nx: {}\n"),
        (".toml", 'kind = "optimal_control"\nx = {}\n'),
    ],
)
@pytest.mark.parametrize("depth", [100, 1000, 5000])
def test_deep_nesting(tmp_path, suffix, template, depth) -> None:
    path = _text(tmp_path, template.format("[" * depth + "]" * depth), f"deep{suffix}")
    _refused(["validate", path], "nested deeper than")


def test_recursive_alias(tmp_path) -> None:
    path = _text(tmp_path, "kind: optimal_control\nx: &a [*a]\n", "loop.yaml")
    _refused(["validate", path], "recursive alias *a", "line 2")


# Accepted by validate, crashing in solve


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("where", ["matrix", "mean", "covariance"])
def test_non_finite_numbers_in_an_lq_game(tmp_path, bad, where) -> None:
    data = _load(LQ)
    if where == "matrix":
        data["problem"]["discrete"]["A"][0][0] = bad
    elif where == "mean":
        data["problem"]["initial"]["mean"][0] = bad
    else:
        data["problem"]["initial"]["covariance"]["diag"][0] = bad
    _refused(["validate", _yaml(tmp_path, data)], "problem.")


@pytest.mark.parametrize(
    ("assignment", "field"),
    [("problem.dynamics.x=1e+300", "problem.dynamics"), ("problem.parameters.s=1e300", "problem.payoff")],
)
def test_huge_entries_of_an_lq_differential_game(assignment, field) -> None:
    """Found by the long solve-path fuzz: ẋ = 1e300 (an affine term) ran the existence test's
    Riccati integration for minutes; now its matrices are checked against MAX_LQ_ENTRY."""
    path = PROBLEMS / "ch7" / "scalar_lq_three_sevenths.yaml"
    outcome = run_cli(["solve", path, "--set", assignment], bound_s=10 * ONE_SECOND)
    assert_promise(outcome, str(path))
    assert outcome.code == 2 and f"{field}: " in outcome.err and "MAX_LQ_ENTRY" in outcome.err, outcome


def test_an_overconstrained_nlp_is_said_in_the_one_line() -> None:
    """Found by the long solve-path fuzz: a control fixed by its bounds (u in [1, 1]) leaves more
    equalities than variables; CasADi printed a warning beside the status line, now the status's
    message says it."""
    path = PROBLEMS / "ocp" / "min_time_double_integrator.yaml"
    outcome = run_cli(["solve", path, "--set", "problem.controls.u.lower=1"], bound_s=10 * ONE_SECOND)
    assert_promise(outcome, str(path))
    assert outcome.code == 1 and "overconstrained" in outcome.err, outcome


def test_a_flow_too_fast_for_its_grid_is_refused_before_the_first_step() -> None:
    """Found by the long solve-path fuzz: a drift of 1e300 passed the load-time bound (the agents'
    speeds) and made the level sets' CFL step 1e-300; the step with the flow is bounded too."""
    path = PROBLEMS / "ch5" / "hurricane_hugo.yaml"
    sets = ["method.grid.nodes=[15, 15]", "method.max_time=1.0", 'problem.flow.drift.1="-1e300"']
    outcome = run_cli(["solve", path, *(x for a in sets for x in ("--set", a))], bound_s=10 * ONE_SECOND)
    assert_promise(outcome, str(path))
    assert outcome.code == 2 and "problem.flow: " in outcome.err and "cell steps" in outcome.err, outcome


@pytest.mark.parametrize("coordinate", [2**63, 1e308])
def test_huge_coordinates_of_an_engagement(tmp_path, coordinate) -> None:
    data = _load(ENGAGEMENT)
    data["pursuers"][0]["position"] = [coordinate, 0.0]
    outcome = _refused(["validate", _yaml(tmp_path, data)], "pursuers.0.position.0", "less than or equal")
    assert "coincide" not in outcome.err


def test_huge_coordinate_in_a_scenario_is_not_called_a_coincidence(tmp_path) -> None:
    data = _load(SCENARIO)
    data["pursuers"]["positions"][0] = [1e308, 0.0]
    outcome = _refused(["validate", _yaml(tmp_path, data)], "pursuers.positions.0.0")
    assert "coincide" not in outcome.err


def test_unknown_ipopt_option_at_load() -> None:
    _refused(
        ["validate", ZERMELO, "--set", "solver.options.casadi.ipopt={bogus_opt: 1}"],
        "solver.options.casadi.ipopt",
        "IPOPT has no option 'bogus_opt'",
    )


def test_misspelled_ipopt_option_gets_the_nearest_name() -> None:
    _refused(
        ["validate", ZERMELO, "--set", "solver.options.casadi.ipopt={hessian_aproximation: limited-memory}"],
        "did you mean 'hessian_approximation'",
    )


def test_ipopt_value_of_the_wrong_kind() -> None:
    _refused(
        ["validate", ZERMELO, "--set", "solver.options.casadi.ipopt={mu_strategy: sometimes}"],
        "IPOPT refuses mu_strategy",
    )


@pytest.mark.parametrize(("key", "value"), [("horizon", "1e12"), ("time_step", "1e-7")])
def test_simulation_sizes(key, value) -> None:
    _refused(["validate", SCENARIO, "--set", f"{key}={value}"], "time_step", "exceed the limit")


def test_monte_carlo_sample_memory(tmp_path) -> None:
    data = _load(LQ)
    data["method"]["monte_carlo"]["samples"] = 1_000_000
    _refused(["validate", _yaml(tmp_path, data)], "method.monte_carlo.samples", "exceed the limit")


def test_collocation_intervals_limit() -> None:
    _refused(["validate", ZERMELO, "--set", "method.intervals=100000000"], "method.intervals")


# Misleading or silent


def test_misspelled_backend_option_fails_validate_with_the_file_and_the_nearest_key() -> None:
    _refused(
        ["validate", ZERMELO, "--set", "solver.options.casadi.max_itr=5"],
        f"{ZERMELO}: solver.options.casadi.max_itr",
        "did you mean 'max_iter'",
    )


@pytest.mark.parametrize("backend", ["pyomo", "cvxpy", "qp", "geometric", "analytic", "study"])
def test_misspelled_option_of_every_backend(backend) -> None:
    _refused(
        ["validate", ZERMELO, "--set", f"solver.options.{backend}.no_such_option=5"],
        f"solver.options.{backend}.no_such_option",
        "unknown key",
    )


def test_misspelled_backend_name_in_options() -> None:
    _refused(["validate", ZERMELO, "--set", "solver.options.casadj.tol=1"], "did you mean 'casadi'")


def test_pyomo_does_not_ignore_unknown_solver_options() -> None:
    _refused(
        ["validate", ZERMELO, "--set", "solver.options.pyomo.options={max_wall_tme: 3}"],
        "solver.options.pyomo.options",
        "no option 'max_wall_tme'",
        "did you mean 'max_wall_time'",
    )


def test_misspelled_parameter_in_set() -> None:
    _refused(
        ["validate", ZERMELO, "--set", "problem.parameters.rhoo=3"],
        "problem.parameters.rhoo",
        "did you mean 'rho'",
        source="--set",
    )


@pytest.mark.parametrize(
    ("name", "text", "needle"),
    [
        ("dup.yaml", "kind: optimal_control\nname: a\nname: b\n", "duplicate key 'name' at line 3"),
        ("dup.json", '{"kind": "optimal_control", "name": "a", "name": "b"}', "duplicate key 'name'"),
    ],
)
def test_duplicate_keys(tmp_path, name, text, needle) -> None:
    _refused(["validate", _text(tmp_path, text, name)], needle)


@pytest.mark.parametrize(
    "args",
    [["validat", ZERMELO], ["validate"], ["solve", ZERMELO, "--no-such-flag"], ["sweep", ZERMELO]],
)
def test_usage_errors_are_one_line(args) -> None:
    outcome = run_cli([str(a) for a in args])
    assert outcome.code == 2
    lines = outcome.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), outcome
    assert "╭" not in outcome.err


def test_warnings_do_not_reach_stderr(monkeypatch) -> None:
    import gamespec.loader

    def noisy(*args, **kwargs):
        warnings.warn("a solver's warning", RuntimeWarning, stacklevel=1)
        np.float64(1e308) * 10
        raise gamespec.SpecError("the reason", field="f", source="noisy.yaml")

    import gamespec

    monkeypatch.setattr(gamespec.loader, "load", noisy)
    outcome = run_cli(["validate", ZERMELO])
    assert outcome.code == 2
    assert outcome.err == "error: noisy.yaml: f: the reason\n"


# Damaged Result files


@pytest.fixture(scope="module")
def saved(tmp_path_factory) -> Path:
    """A solved Zermelo Result folder (copied by each case before it damages it)."""
    folder = tmp_path_factory.mktemp("saved") / "run"
    assert run_cli(["solve", ZERMELO, "--out", folder], bound_s=60).code == 0
    return folder


def _damaged(saved: Path, tmp_path: Path, damage) -> Path:
    folder = tmp_path / "run"
    folder.mkdir()
    for name in ("result.json", "arrays.npz"):
        (folder / name).write_bytes((saved / name).read_bytes())
    damage(folder / "arrays.npz")
    return folder


def _zero_bytes(npz: Path) -> None:
    npz.write_bytes(b"")


def _bad_deflate(npz: Path) -> None:
    raw = bytearray(npz.read_bytes())
    for i in range(120, 220):
        raw[i] ^= 0x5A
    npz.write_bytes(bytes(raw))


def _short_state(npz: Path) -> None:
    arrays = dict(np.load(npz))
    arrays["states/x1"] = arrays["states/x1"][:-2]
    np.savez(npz, **arrays)


def _nan_time(npz: Path) -> None:
    arrays = dict(np.load(npz))
    arrays["time"][1] = np.nan
    np.savez(npz, **arrays)


@pytest.mark.parametrize("damage", [_zero_bytes, _bad_deflate, _short_state, _nan_time])
def test_plot_of_a_damaged_result(saved, tmp_path, damage) -> None:
    folder = _damaged(saved, tmp_path, damage)
    outcome = run_cli(["plot", folder])
    assert_promise(outcome, str(folder / "arrays.npz"))
    assert outcome.code == 2 and "not a readable Result" in outcome.err


@pytest.mark.parametrize("damage", [_zero_bytes, _short_state])
def test_guess_from_a_damaged_result(saved, tmp_path, damage) -> None:
    folder = _damaged(saved, tmp_path, damage)
    outcome = run_cli(["solve", ZERMELO, "--set", f"guess.result={folder}"])
    assert_promise(outcome, str(ZERMELO))
    assert outcome.code == 2 and "guess.result" in outcome.err and "arrays.npz" in outcome.err


def test_plot_of_a_failed_solve(tmp_path) -> None:
    folder = tmp_path / "failed"
    outcome = run_cli(
        ["solve", ZERMELO, "--set", "solver.options.casadi.max_iter=1", "--out", folder, "--plot"]
    )
    assert_promise(outcome)
    assert outcome.code == 1 and "iteration_limit" in outcome.err
    assert json.loads((folder / "result.json").read_text())["objective"] is None
    replot = run_cli(["plot", folder, "--out", tmp_path / "plots"])
    assert replot.code == 0, replot
    assert list((tmp_path / "plots").glob("*.png"))


# Wrong statuses


def test_casadi_calls_ipopts_infeasibility_local() -> None:
    """|x2| <= t, so x1(t_f) <= t_f + rho t_f^2 / 2 = 0.4 < 2 for t_f <= 0.2: no feasible point, and
    IPOPT can only say that it found none near where it looked."""
    outcome = run_cli(["solve", ZERMELO, "--json", "--set", "problem.time.bounds=[0.05, 0.2]"], bound_s=60)
    assert_promise(outcome)
    assert outcome.code == 1
    assert json.loads(outcome.out)["status"] == "locally_infeasible"


def test_local_solvers_never_claim_infeasibility_is_proven() -> None:
    from gamespec_casadi.backend import STATUS_MAP as CASADI
    from gamespec_pyomo.solvers import STATUS_MAP as PYOMO

    from gamespec.result import Status

    assert Status.INFEASIBLE not in set(CASADI.values()) | set(PYOMO.values())
    assert CASADI["Infeasible_Problem_Detected"] is PYOMO["infeasible"] is Status.LOCALLY_INFEASIBLE
    assert not Status.LOCALLY_INFEASIBLE.ok


@pytest.mark.parametrize(
    ("value", "needle"),
    [
        ("&a [*a]", "recursive alias"),
        ("9" * (MAX_INT_DIGITS + 1), "digits"),
        ("{a: 1, a: 2}", "duplicate key"),
    ],
)
def test_set_values_are_read_within_the_limits_of_a_file(value, needle) -> None:
    _refused(["validate", ZERMELO, "--set", f"name={value}"], needle, source="--set")


def test_sweep_grid_limit() -> None:
    _refused(
        ["sweep", ZERMELO, "--param", "rho=1:2:1000", "--param", "xf=1:2:1000", "--out", "unused"],
        "grid points exceed the limit",
        source="--param",
    )


FILE = "{file}"
COMMANDS = [
    ["validate", FILE],
    ["solve", FILE],
    ["solve", FILE, "--json"],
    ["compare", FILE, "--backends", "casadi,pyomo"],
    ["sweep", FILE, "--param", "rho=1:2:2", "--out", "unused"],
    ["show", FILE],
    ["show", FILE, "--transformed"],
    ["pursuit", "study", FILE],
]


@pytest.mark.parametrize("command", COMMANDS, ids=lambda c: " ".join(c[:2]))
@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("latin.yaml", b"kind: optimal_control\nname: \xff\n"),
        ("loop.yaml", b"kind: optimal_control\nx: &a [*a]\n"),
        ("dash.json", b'{"kind": "engagement", "capture-radius": 1}'),
    ],
)
def test_every_command_refuses_a_bad_file_in_one_line(tmp_path, command, name, content) -> None:
    path = _text(tmp_path, content, name)
    outcome = run_cli([str(path) if part == FILE else part for part in command])
    assert_promise(outcome, str(path))
    assert outcome.code == 2


@pytest.mark.parametrize(
    ("expression", "needle"),
    [
        ("exp(exp(exp(100)))", "out of range"),
        ("x1*1e300*1e300", "out of range"),
        ("max(exp(exp(exp(9))), u)", "out of range"),
        ("sin(10**400)", "out of range"),
    ],
)
def test_expressions_are_evaluated_in_floating_point(expression, needle) -> None:
    _refused(
        ["validate", ZERMELO, "--set", f"problem.dynamics.x1={expression}"], "problem.dynamics.x1", needle
    )


def test_float_value_agrees_with_sympy_where_sympy_is_quick() -> None:
    import sympy as sp

    from gamespec.symbolic.language import float_value

    x = sp.Integer(3)
    for expr in (sp.sqrt(x) * sp.pi, sp.exp(x) - sp.log(x), sp.atan2(x, -x), sp.Max(sp.sin(x), sp.cos(x))):
        assert float_value(expr) == pytest.approx(float(expr), rel=1e-14)
    with pytest.raises(OverflowError):
        float_value(sp.exp(sp.exp(sp.exp(sp.Integer(100)))))


def test_file_size_limit(tmp_path) -> None:
    from gamespec.limits import MAX_FILE_BYTES

    path = _text(tmp_path, "kind: optimal_control\n" + "#" * MAX_FILE_BYTES + "\n", "big.yaml")
    _refused(["validate", path], f"larger than the limit of {MAX_FILE_BYTES} bytes")


def test_many_values_without_aliases(tmp_path) -> None:
    path = _text(tmp_path, json.dumps({"kind": "optimal_control", "x": [0] * MAX_VALUES}), "many.json")
    _refused(["validate", path], f"more than {MAX_VALUES} values")
