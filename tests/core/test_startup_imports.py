"""Start-up guards (issue 16, item 2): what a command imports, read from ``sys.modules`` in a fresh
interpreter after the command ran. Structural, not timed: ``gamespec --help`` needs neither NumPy,
SymPy, SciPy, rich nor a backend (pydantic is not checked: typer may import it to read parameter
types); ``validate`` of a file whose bounds use no functions neither NumPy, SymPy nor a solver (the
whitelist walk in floats); a CasADi solve of an ``optimal_control`` file neither SymPy (its terms
are built from the text), SciPy nor another backend, and with ``--json`` where stderr is no
terminal not rich either (no spinner to draw). The plugin registry reads the installed
distributions' entry points once for all groups. The CPU times themselves are
measured in ``benchmarks/test_bench_startup.py``."""

from __future__ import annotations

import json
import subprocess
import sys
from functools import cache

import pytest

from gamespec import registry
from tests.conftest import PROBLEMS

FILE = str(PROBLEMS / "ch6" / "zermelo_min_time.yaml")
PROBE = """
import contextlib, io, json, sys
from gamespec.cli import run
with contextlib.redirect_stdout(io.StringIO()):
    code = run(sys.argv[1:])
print(json.dumps({"code": code, "modules": sorted({m.split(".")[0] for m in sys.modules})}))
"""
SOLVERS = {"casadi", "pyomo", "cvxpy", "qpsolvers", "clarabel", "scs", "osqp", "proxsuite"}
BACKENDS = {"gamespec_casadi", "gamespec_pyomo", "gamespec_cvxpy", "gamespec_qp", "gamespec_geometric"}


def imported_by(*argv: str) -> set[str]:
    """The top-level packages in ``sys.modules`` once ``gamespec ARGV`` has run (exit code 0)."""
    done = subprocess.run([sys.executable, "-c", PROBE, *argv], capture_output=True, text=True, check=True)
    report = json.loads(done.stdout.splitlines()[-1])
    assert report["code"] == 0, done.stderr
    return set(report["modules"])


@pytest.mark.parametrize("argv", [["--help"], ["solve", "--help"]])
def test_help_imports_no_heavy_package(argv: list[str]) -> None:
    heavy = {"numpy", "sympy", "scipy", "rich", "yaml", "matplotlib", *SOLVERS, *BACKENDS}
    assert imported_by(*argv) & heavy == set()


def test_validate_imports_no_numpy_no_sympy_and_no_solver() -> None:
    heavy = {"numpy", "sympy", "scipy", "matplotlib", *SOLVERS, *BACKENDS}
    assert imported_by("validate", FILE) & heavy == set()


def test_casadi_solve_imports_no_sympy_no_scipy_and_no_other_backend() -> None:
    modules = imported_by("solve", FILE)
    assert {"casadi", "gamespec_casadi"} <= modules
    others = {*(SOLVERS - {"casadi"}), *(BACKENDS - {"gamespec_casadi"})}
    assert modules & {"sympy", "scipy", "matplotlib", *others} == set()


def test_json_solve_without_a_terminal_imports_no_rich() -> None:
    assert "rich" not in imported_by("solve", FILE, "--json")


def test_registry_reads_the_installed_entry_points_once_for_all_groups(monkeypatch) -> None:
    reads = []
    installed = registry.entry_points

    def counted():
        reads.append(1)
        return installed()

    monkeypatch.setattr(registry, "entry_points", counted)
    monkeypatch.setattr(registry, "_installed", cache(registry._installed.__wrapped__))
    monkeypatch.setattr(registry, "_entry_points", cache(registry._entry_points.__wrapped__))
    found = {group: registry.names(group) for group in registry.GROUPS}
    assert len(reads) == 1
    assert {"casadi", "pyomo"} <= set(found["gamespec.backends"])
    assert "optimal_control" in found["gamespec.kinds"]
