"""Bad input: exit code 2 and one line naming the file, the field and the reason (issue 2, item 8)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

from tests.conftest import PROBLEMS

ZERMELO = PROBLEMS / "ch6" / "zermelo_min_time.yaml"


def _write(tmp_path: Path, data: dict | str, name: str = "p.yaml") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return path


def _base() -> dict:
    return yaml.safe_load(ZERMELO.read_text())


def _assert_one_line(code: int, err: str, *needles: str) -> None:
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])


def test_missing_file(cli, tmp_path) -> None:
    code, _, err = cli("validate", tmp_path / "absent.yaml")
    _assert_one_line(code, err, "absent.yaml", "file not found")


def test_bad_yaml(cli, tmp_path) -> None:
    path = _write(tmp_path, "kind: optimal_control\nproblem: [unclosed\n")
    code, _, err = cli("validate", path)
    _assert_one_line(code, err, "p.yaml", "malformed YAML")


def test_unknown_key_suggests_the_nearest(cli, tmp_path) -> None:
    data = _base()
    data["problem"]["states"]["x1"]["intial"] = data["problem"]["states"]["x1"].pop("initial")
    code, _, err = cli("validate", _write(tmp_path, data))
    _assert_one_line(code, err, "p.yaml", "problem.states.x1.intial", "did you mean 'initial'")


def test_unknown_top_level_section(cli, tmp_path) -> None:
    data = _base() | {"methd": {"intervals": 3}}
    code, _, err = cli("validate", _write(tmp_path, data))
    _assert_one_line(code, err, "methd", "did you mean 'method'")


def test_wrong_type(cli, tmp_path) -> None:
    data = _base()
    data["method"]["intervals"] = "many"
    code, _, err = cli("validate", _write(tmp_path, data))
    _assert_one_line(code, err, "method.intervals", "integer")


def test_undefined_symbol(cli, tmp_path) -> None:
    data = _base()
    data["problem"]["dynamics"]["x2"] = "sin(u) + wind"
    code, _, err = cli("validate", _write(tmp_path, data))
    _assert_one_line(code, err, "problem.dynamics.x2", "undefined symbol 'wind'")


def test_dangerous_expression(cli, tmp_path) -> None:
    data = _base()
    data["problem"]["dynamics"]["x2"] = "__import__('os').system('echo hacked')"
    code, out, err = cli("validate", _write(tmp_path, data))
    _assert_one_line(code, err, "problem.dynamics.x2", "__import__")
    assert "hacked" not in out


def test_dimension_mismatch_dynamics_per_state(cli, tmp_path) -> None:
    data = _base()
    del data["problem"]["dynamics"]["x2"]
    code, _, err = cli("validate", _write(tmp_path, data))
    _assert_one_line(code, err, "problem", "no dynamics for ['x2']")


def test_unknown_kind(cli, tmp_path) -> None:
    code, _, err = cli("validate", _write(tmp_path, {"kind": "optimal_contrl"}))
    _assert_one_line(code, err, "kind", "unknown kind 'optimal_contrl'")


def test_free_time_without_bounds(cli, tmp_path) -> None:
    data = _base()
    del data["problem"]["time"]["bounds"]
    code, _, err = cli("validate", _write(tmp_path, data))
    _assert_one_line(code, err, "problem.time", "needs bounds")


def test_unknown_backend(cli) -> None:
    code, _, err = cli("solve", ZERMELO, "--backend", "nosuch")
    _assert_one_line(code, err, "unknown backend 'nosuch'")


def test_backend_lacking_a_kind(cli, tmp_path, monkeypatch) -> None:
    from gamespec_casadi.backend import CasadiBackend

    monkeypatch.setattr(CasadiBackend, "features", frozenset({"ode"}))
    code, _, err = cli("solve", ZERMELO)
    _assert_one_line(code, err, "lacks free_final_time")


def test_bad_set_override(cli) -> None:
    code, _, err = cli("solve", ZERMELO, "--set", "no_equals_sign")
    _assert_one_line(code, err, "--set expects dotted.path=value")


def test_bad_backend_option(cli) -> None:
    code, _, err = cli("solve", ZERMELO, "--set", "solver.options.casadi.max_itr=5")
    _assert_one_line(code, err, "solver.options.casadi.max_itr")


def test_unknown_parameter_in_python_api() -> None:
    import gamespec

    solver = gamespec.compile_spec(ZERMELO)
    with pytest.raises(gamespec.SpecError, match="unknown parameter 'rh'"):
        solver.solve(parameters={"rh": 2.0})


def test_failed_solve_is_a_result_with_exit_1(cli) -> None:
    code, out, err = cli("solve", ZERMELO, "--json", "--set", "solver.options.casadi.max_iter=1")
    assert code == 1
    assert json.loads(out)["status"] == "iteration_limit"
    assert "iteration_limit" in err.strip().splitlines()[-1]


@pytest.mark.parametrize("suffix", [".toml", ".json"])
def test_toml_and_json_files_load_like_yaml(tmp_path, suffix) -> None:
    import tomllib

    import gamespec

    data = _base()
    path = tmp_path / f"p{suffix}"
    if suffix == ".json":
        path.write_text(json.dumps(data))
    else:
        path.write_text(_to_toml(data))
        assert tomllib.loads(path.read_text()) == data
    assert gamespec.load(path).model_dump() == gamespec.load(ZERMELO).model_dump()


def _to_toml(data: dict, prefix: str = "") -> str:
    """A tiny TOML writer for the nested test data (tables of scalars and lists)."""
    scalars, tables = [], []
    for key, value in data.items():
        if isinstance(value, dict):
            tables.append(f"\n[{prefix}{key}]\n" + _to_toml(value, f"{prefix}{key}."))
        else:
            scalars.append(f"{key} = {json.dumps(value)}\n")
    return "".join(scalars) + "".join(tables)


@pytest.mark.parametrize(
    ("edit", "needles"),
    [
        (
            lambda d: d["problem"]["controls"].update(u={"lower": "pi", "upper": "-pi"}),
            ["controls.u", "exceeds"],
        ),
        (lambda d: d["problem"]["states"]["x2"].update(lower=1, upper=-1), ["states.x2", "exceeds"]),
        (lambda d: d["problem"]["states"]["x1"].update(upper=-1), ["states.x1.initial", "outside"]),
        (
            lambda d: d["problem"].update(path_constraints=["3 <= x1 <= 1"]),
            ["path_constraints.0", "empty range"],
        ),
        (lambda d: d["problem"]["parameters"].update(rho=float("nan")), ["problem.parameters.rho", "finite"]),
        (lambda d: d["method"].update(grading=float("inf")), ["method.grading"]),
        (lambda d: d["problem"]["controls"]["u"].update(upper="pi/0"), ["controls.u.upper", "infinite"]),
        (lambda d: d["problem"]["dynamics"].update(x2="9**9**9"), ["dynamics.x2", "out of range"]),
        (
            lambda d: d["problem"]["dynamics"].update(x2="-" * 3000 + "u"),
            ["dynamics.x2", "nested too deeply"],
        ),
    ],
)
def test_values_that_cannot_be_solved_are_refused_at_load(cli, tmp_path, edit, needles) -> None:
    data = _base()
    edit(data)
    code, _, err = cli("validate", _write(tmp_path, data))
    _assert_one_line(code, err, "p.yaml", *needles)


def test_a_parameter_override_that_empties_a_bound_is_exit_2(cli) -> None:
    code, _, err = cli(
        "solve", ZERMELO, "--set", "problem.parameters.xf=-1", "--set", "problem.states.x1.lower=0"
    )
    _assert_one_line(code, err, "zermelo_min_time.yaml", "states.x1.final", "outside")


@pytest.mark.parametrize("content", [None, "{}", '{"a": 1}', "[1, 2]", "not json"])
def test_plot_of_something_that_is_not_a_result(cli, tmp_path, content) -> None:
    target = tmp_path / "run"
    target.mkdir()
    if content is not None:
        (target / "result.json").write_text(content)
    code, _, err = cli("plot", target)
    _assert_one_line(code, err, "not a readable Result")


def test_plot_of_a_corrupt_array_file(cli, tmp_path) -> None:
    code, _, _ = cli("solve", ZERMELO, "--out", tmp_path / "run")
    assert code == 0
    (tmp_path / "run" / "arrays.npz").write_bytes(b"garbage")
    code, _, err = cli("plot", tmp_path / "run")
    _assert_one_line(code, err, "not a readable Result")


def test_out_that_cannot_be_written_is_refused_before_solving(cli, tmp_path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("x")
    code, out, err = cli("solve", ZERMELO, "--out", blocker)
    _assert_one_line(code, err, "cannot write there")
    assert out == ""


def test_compare_survives_a_backend_error_and_fails_when_nothing_solved(cli) -> None:
    code, out, err = cli("compare", ZERMELO, "--backends", "casadi,casadi:nosuchsolver", "--json")
    rows = json.loads(out)
    assert code == 0
    assert [r["status"] for r in rows] == ["optimal", "unsupported"]
    assert "nosuchsolver" in rows[1]["reason"]
    code, _, err = cli("compare", ZERMELO, "--backends", "nosuch")
    assert code == 1 and "no backend solved" in err.strip().splitlines()[-1]
