"""The CLI surface of DESIGN.md: solve --json fields, --out and plot, schema, backends, show."""

from __future__ import annotations

import json
import subprocess
import sys

import yaml

import gamespec
from gamespec import registry
from gamespec.compiling import Availability
from gamespec.loader import spec_from_dict
from gamespec.specs.schema import json_schema
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


def test_schema_describes_every_kind_and_the_fields_files_use(cli) -> None:
    """The schema of one kind lists exactly its spec's fields; the schema of all files is the union
    discriminated by ``kind`` over every registered kind; every key of every shipped file is a
    property of its kind's schema."""
    code, out, _ = cli("schema", "optimal_control")
    assert code == 0
    schema = json.loads(out)
    assert set(schema["properties"]) == set(registry.spec_class("optimal_control").model_fields)
    assert "problem" in schema["required"]
    code, out, _ = cli("schema")
    assert code == 0
    union = json.loads(out)
    assert union["discriminator"]["propertyName"] == "kind"
    assert set(union["discriminator"]["mapping"]) == set(registry.names("gamespec.kinds"))
    for path in PROBLEMS.glob("*/*.yaml"):
        data = yaml.safe_load(path.read_text())
        properties = json_schema(data["kind"])["properties"]
        assert set(data) <= set(properties), path
    code, _, err = cli("schema", "no_such_kind")
    assert code == 2 and "unknown kind 'no_such_kind'" in err


def test_backends_lists_each_backend_with_its_availability(cli, monkeypatch) -> None:
    """One row per registered backend, led by its name and first kind; an unavailable backend says
    no, with its reason."""
    analytic = registry.backend_class("analytic")
    monkeypatch.setattr(analytic, "available", classmethod(lambda cls: Availability(False, "gone fishing")))
    code, out, _ = cli("backends")
    assert code == 0
    lines = out.splitlines()
    for name in registry.names("gamespec.backends"):
        first_kind = sorted(registry.backend_class(name).kinds)[0]
        row = next(line for line in lines if line.split()[:1] == [name])
        assert row.split()[1] == first_kind
        assert ("no: gone fishing" in row) == (name == "analytic")
        assert ("yes:" in row) == registry.backend_class(name).available().ok


def test_show_prints_the_validated_spec(cli) -> None:
    """What show prints validates back into the same spec, with the overrides applied."""
    code, out, _ = cli("show", ZERMELO, "--set", "problem.parameters.rho=3")
    assert code == 0
    data = yaml.safe_load(out)
    expected = gamespec.load(ZERMELO, ["problem.parameters.rho=3"])
    assert spec_from_dict(data).model_dump() == expected.model_dump()
    assert data["problem"]["parameters"]["rho"] == 3.0
    assert data["problem"]["dynamics"]["x1"] == "cos(u) + rho*x2"


def test_show_transformed_prints_the_generated_ocp(cli) -> None:
    """An engagement shows as the reduced OCP the backend solves (eq. 2.21 for two pure pursuers)."""
    engagement = PROBLEMS / "ch2" / "pure_pursuit_two_on_one.yaml"
    code, out, _ = cli("show", engagement, "--transformed")
    assert code == 0
    data = yaml.safe_load(out)
    assert data["kind"] == "optimal_control"
    assert data == gamespec.compile_spec(engagement).target_spec.model_dump(mode="json")
    assert data["problem"]["dynamics"]["r1"] == "-u1 + v*cos(theta)"


def test_importing_gamespec_does_not_import_solvers() -> None:
    code = "import sys, gamespec; print(sorted(m for m in ('casadi', 'pyomo', 'cvxpy') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]"
