"""``gamespec compare`` with the two OCP backends: one row each, the same discretization, a table
that fits an 80-column terminal, reasons instead of a stopped study, saved Results."""

from __future__ import annotations

import io
import json

import pytest
from gamespec_pyomo import solvers
from rich.console import Console

import gamespec
from gamespec.errors import BackendError
from gamespec.result import Result
from gamespec.studies.compare import compare_backends, comparison_table, parse_backend_list
from tests.conftest import PROBLEMS
from tests.pyomo.cases import atan2_file

MAX_RANGE = PROBLEMS / "ch6" / "zermelo_max_range.yaml"
KEYS = {
    "status",
    "objective",
    "t_final",
    "build_time_s",
    "solve_time_s",
    "iterations",
    "max_constraint_violation",
    "max_defect",
    "relative_gap",
}


def test_backend_list_parses_solvers() -> None:
    assert parse_backend_list("casadi, pyomo:ripopt") == [("casadi", None), ("pyomo", "ripopt")]
    with pytest.raises(BackendError):
        parse_backend_list("casadi,,pyomo")


def test_json_rows_agree_across_backends(cli) -> None:
    code, out, _ = cli("compare", MAX_RANGE, "--backends", "casadi,pyomo", "--json")
    assert code == 0
    rows = json.loads(out)
    assert [r["backend"] for r in rows] == ["casadi", "pyomo"]
    for row in rows:
        assert row.keys() >= KEYS
        assert row["status"] == "optimal"
        assert row["relative_gap"] < 1e-4
    assert min(r["relative_gap"] for r in rows) == 0.0
    assert rows[0]["t_final"] == rows[1]["t_final"]


def test_table_fits_80_columns(monkeypatch) -> None:
    """Every column at its natural width, the longest backend label and status included."""
    monkeypatch.setattr(solvers.shutil, "which", lambda name: None)
    spec = gamespec.load(MAX_RANGE)
    rows = compare_backends(spec, parse_backend_list("casadi,pyomo:ripopt,pyomo:ipopt"))
    rows.append({**rows[0], "backend": "casadi:ipopt", "status": "iteration_limit", "objective": -123.456789})
    console = Console(width=80, file=io.StringIO())
    table = comparison_table(rows, "zermelo_max_range: backend comparison")
    assert console.measure(table).maximum <= 80
    console.print(table)
    assert "…" not in console.file.getvalue()


def test_reasons_are_printed_under_the_table(cli, monkeypatch) -> None:
    monkeypatch.setattr(solvers.shutil, "which", lambda name: None)
    code, out, _ = cli("compare", MAX_RANGE, "--backends", "casadi,pyomo:ipopt,nosuch")
    assert code == 0
    below = out[out.index("build, solve:") :]
    assert "pyomo:ipopt: no ipopt executable on PATH" in below
    assert "nosuch: unknown backend 'nosuch'" in below


def test_a_backend_that_cannot_take_the_problem_gets_a_row(cli, tmp_path) -> None:
    code, out, _ = cli("compare", atan2_file(tmp_path), "--backends", "pyomo,casadi", "--json")
    assert code == 0
    pyomo, casadi = json.loads(out)
    assert pyomo["status"] == "unsupported" and "atan2" in pyomo["reason"]
    # casadi solves it; its coarse mesh's relative defect (1e-4) keeps it from optimal, and the row
    # names that check
    assert casadi["status"] == "feasible" and "max_defect_relative" in casadi["failed_checks"]


def test_out_saves_each_result(cli, tmp_path) -> None:
    code, out, _ = cli("compare", MAX_RANGE, "--backends", "casadi,pyomo:ripopt", "--out", tmp_path, "--json")
    assert code == 0
    rows = {r["backend"]: r for r in json.loads(out)}
    for label, folder in (("casadi", "casadi"), ("pyomo:ripopt", "pyomo_ripopt")):
        saved = Result.load(tmp_path / folder)
        assert saved.objective == rows[label]["objective"]
        assert saved.states["x1"].shape == saved.time.shape
