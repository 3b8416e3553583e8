"""The CLI surface of DESIGN.md: solve --json fields, --out and plot, schema, backends, show."""

from __future__ import annotations

import json
import subprocess
import sys

from tests.conftest import PROBLEMS

ZERMELO = PROBLEMS / "ch6" / "zermelo_min_time.yaml"


def test_solve_json_has_the_documented_fields(cli) -> None:
    code, out, _ = cli("solve", ZERMELO, "--json")
    data = json.loads(out)
    assert code == 0
    for key in ("status", "objective", "backend", "solve_time_s", "t_final"):
        assert key in data
    assert data["status"] == "optimal"
    assert data["objective"] == data["t_final"]


def test_set_overrides_a_parameter(cli) -> None:
    _, base, _ = cli("solve", ZERMELO, "--json")
    _, moved, _ = cli("solve", ZERMELO, "--json", "--set", "problem.parameters.xf=1.0")
    assert json.loads(moved)["t_final"] < json.loads(base)["t_final"]
    assert json.loads(moved)["parameters"]["xf"] == 1.0


def test_out_then_plot(cli, tmp_path) -> None:
    code, out, _ = cli("solve", ZERMELO, "--out", tmp_path / "run")
    assert code == 0 and "saved" in out
    assert (tmp_path / "run" / "result.json").exists()
    assert (tmp_path / "run" / "arrays.npz").exists()
    code, out, _ = cli("plot", tmp_path / "run")
    assert code == 0
    pngs = sorted(p.name for p in (tmp_path / "run").glob("*.png"))
    assert pngs == ["zermelo_min_time_path.png", "zermelo_min_time_time.png"]


def test_schema_and_backends(cli) -> None:
    code, out, _ = cli("schema", "optimal_control")
    schema = json.loads(out)
    assert code == 0 and "problem" in schema["properties"]
    code, out, _ = cli("schema")
    assert code == 0 and json.loads(out)
    code, out, _ = cli("backends")
    assert code == 0 and "casadi" in out


def test_show_prints_the_validated_spec(cli) -> None:
    import yaml

    code, out, _ = cli("show", ZERMELO)
    data = yaml.safe_load(out)
    assert code == 0
    assert data["problem"]["dynamics"]["x1"] == "cos(u) + rho*x2"
    assert data["method"]["scheme"] == "radau"


def test_importing_gamespec_does_not_import_solvers() -> None:
    code = "import sys, gamespec; print(sorted(m for m in ('casadi', 'pyomo', 'cvxpy') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
