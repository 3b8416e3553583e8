"""Finding the NLP executable, reading its log, and mapping its statuses."""

from __future__ import annotations

import os

import pytest
from gamespec_pyomo import solvers
from gamespec_pyomo.backend import PyomoBackend

import gamespec
from gamespec.errors import BackendError
from gamespec.result import Status
from tests.conftest import PROBLEMS


def _path_with(monkeypatch, *names: str) -> None:
    monkeypatch.setattr(solvers.shutil, "which", lambda name: f"/opt/bin/{name}" if name in names else None)


def test_ipopt_on_path_is_preferred(monkeypatch) -> None:
    _path_with(monkeypatch, "ipopt")
    exe = solvers.find_executable("auto")
    assert (exe.name, exe.path, exe.origin) == ("ipopt", "/opt/bin/ipopt", "on PATH")
    assert solvers.find_executable("ripopt").origin.startswith("bundled with pyomo-ripopt")


def test_bundled_ripopt_is_the_default(monkeypatch) -> None:
    _path_with(monkeypatch)
    assert solvers.find_executable("auto").name == "ripopt"
    availability = PyomoBackend.available()
    assert availability.ok
    assert "ripopt (bundled with pyomo-ripopt" in availability.reason


def test_asking_for_a_missing_ipopt_says_why(monkeypatch) -> None:
    _path_with(monkeypatch)
    with pytest.raises(BackendError, match="no ipopt executable on PATH"):
        solvers.find_executable("ipopt")


def test_no_executable_at_all_makes_the_backend_unavailable(monkeypatch) -> None:
    _path_with(monkeypatch)
    monkeypatch.setattr(solvers, "_bundled_ripopt", lambda: None)
    availability = PyomoBackend.available()
    assert not availability.ok
    assert "bundled ripopt is missing" in availability.reason


@pytest.mark.parametrize(
    ("termination", "message", "status"),
    [
        ("optimal", "ripopt 0.8.2: Optimal Solution Found", Status.OPTIMAL),
        ("optimal", "Ipopt 3.14.16: Solved To Acceptable Level.", Status.FEASIBLE),
        ("maxIterations", "Maximum Number of Iterations Exceeded", Status.ITERATION_LIMIT),
        ("infeasible", "Converged to a point of local infeasibility", Status.LOCALLY_INFEASIBLE),
        ("internalSolverError", "Restoration Failed", Status.NUMERICAL_ERROR),
        ("somethingNew", "", Status.ERROR),
    ],
)
def test_status_map(termination: str, message: str, status: Status) -> None:
    assert solvers.status_of(termination, message) is status


def test_iterations_and_seconds_from_either_log() -> None:
    ripopt = "ripopt 0.8.2: Optimal after 8 iterations\n--- ripopt diagnostics ---\n"
    ripopt += "iterations: 8\nwall_time: 0.161s\n"
    ipopt = "Number of Iterations....: 15\n\nTotal seconds in IPOPT                               = 0.012\n"
    assert (solvers.iterations_in(ripopt), solvers.solver_seconds_in(ripopt)) == (8, 0.161)
    assert (solvers.iterations_in(ipopt), solvers.solver_seconds_in(ipopt)) == (15, 0.012)
    assert solvers.iterations_in("no count here") is None
    assert solvers.solver_seconds_in("no time here") is None


def test_a_real_solve_reports_iterations_and_solver_time() -> None:
    result = gamespec.solve(PROBLEMS / "ch6" / "zermelo_min_time.yaml", "pyomo")
    assert result.iterations is not None and result.iterations > 0
    assert 0 < result.solver_stats["solver_time_s"] <= result.solve_time_s


def test_an_ipopt_on_path_is_used_by_default(tmp_path, monkeypatch) -> None:
    """ripopt speaks Ipopt's AMPL interface, so a link named ``ipopt`` stands in for an Ipopt
    install: auto picks it and Pyomo drives it through its ipopt plugin."""
    (tmp_path / "ipopt").symlink_to(solvers.find_executable("ripopt").path)
    monkeypatch.setenv("PATH", f"{tmp_path}{os.pathsep}{os.environ['PATH']}")
    path = PROBLEMS / "ch6" / "zermelo_min_time.yaml"
    on_path = gamespec.solve(path, "pyomo")
    bundled = gamespec.solve(path, "pyomo", options={"solver": "ripopt"})
    assert on_path.solver_stats["solver"] == "ipopt"
    assert on_path.solver_stats["executable"] == str(tmp_path / "ipopt")
    assert bundled.solver_stats["solver"] == "ripopt"
    assert on_path.objective == pytest.approx(bundled.objective, rel=1e-10)


def test_options_file_options_reach_the_solvers_working_directory(tmp_path) -> None:
    """``OF_key`` options (Ipopt's options file: every Ipopt option, also those its AMPL driver does
    not list) are written to ``<name>.opt`` where the solver runs, the others go on its command line."""
    import stat

    seen = tmp_path / "seen"
    fake = tmp_path / "ipopt"
    fake.write_text(f'#!/bin/sh\ncat ipopt.opt > "{seen}.opt"\necho "$@" > "{seen}.args"\nexit 3\n')
    fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
    with pytest.raises(BackendError, match="exit status 3"):
        options = {"tol": 1e-8, "OF_mumps_permuting_scaling": 0}
        solvers.run_solver(solvers.Executable("ipopt", str(fake), "test"), "", options)
    assert (tmp_path / "seen.opt").read_text() == "mumps_permuting_scaling 0\n"
    assert "tol=1e-08" in (tmp_path / "seen.args").read_text()
    assert "mumps" not in (tmp_path / "seen.args").read_text()
