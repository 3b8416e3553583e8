"""The compiled level-set step (:mod:`gamespec.flowfield.compiled`) against the NumPy operator and
the exact disks of a uniform flow; the engine a solve uses; the reachability stage's time limit
and progress line (:mod:`gamespec.flowfield.budget`)."""

from __future__ import annotations

import copy
import time

import numpy as np
import pytest

from gamespec import terminal
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.levelset import LevelSetSolver, initial_cones
from gamespec.loader import spec_from_dict
from gamespec.result import Status
from gamespec.solving import solve
from tests.flowfield.conftest import UNIFORM_DRIFT
from tests.flowfield.test_stages import _spec


def _varied_flow(n: int) -> tuple[Grid, FlowHamiltonian]:
    grid = Grid((-2.0, -1.5), (2.0, 2.5), (n, n + 4))
    x, y = grid.points[..., 0], grid.points[..., 1]
    drift = np.stack([0.3 + 0.2 * np.sin(y), -0.4 * np.cos(x) + 0.1 * x], axis=-1)
    return grid, FlowHamiltonian(np.array([1.0, 0.6]), drift)


def test_compiled_step_equals_the_numpy_operator() -> None:
    """Both agents, a sign-changing drift (every upwind branch), the whole grid and a band box:
    the same φ to rounding after a few steps (the same formulas in another order)."""
    grid, hamiltonian = _varied_flow(41)
    phi = initial_cones(grid, np.array([[-0.5, 0.0], [0.7, 0.9]]))
    for band in (None, 0.8):
        compiled = LevelSetSolver(grid, hamiltonian, "weno5", 0.5, "compiled").propagate(phi, 0.2, band)
        numpy = LevelSetSolver(grid, hamiltonian, "weno5", 0.5, "numpy").propagate(phi, 0.2, band)
        assert np.abs(compiled - numpy).max() < 1e-12


@pytest.mark.parametrize("n", [41, 81])
def test_compiled_step_meets_the_exact_disks_of_a_uniform_flow(n: int) -> None:
    """φ at t = 0.5 against ``max(|x − x₀ − ft| − v̂t, 0)`` on the band 0.3 … 1 above the set (the
    disks of radius v̂t + c about x₀ + ft): within the WENO5 grid error, 5 dx² (the NumPy engine's
    errors are 1.2e-3 and 2.4e-4 at these grids, ``test_levelset``)."""
    grid = Grid((-2.0, -2.0), (2.0, 2.0), (n, n))
    hamiltonian = FlowHamiltonian(np.array([1.0]), np.broadcast_to(UNIFORM_DRIFT, (n, n, 2)))
    solver = LevelSetSolver(grid, hamiltonian, "weno5", 0.5)
    assert solver.compiled
    phi = solver.propagate(initial_cones(grid, np.zeros((1, 2))), 0.5)[0]
    distance = np.linalg.norm(grid.points - UNIFORM_DRIFT * 0.5, axis=-1) - 0.5
    band = (distance >= 0.3) & (distance <= 1.0)
    assert np.abs(phi - distance)[band].max() < 5 * grid.spacing.max() ** 2


def _solved(options: dict, **method: object):
    data = copy.deepcopy(_spec())
    data["method"] |= method
    data["solver"] = {"options": {"levelset": {"cross_check": False, **options}}}
    return solve(spec_from_dict(data))


def test_the_default_engine_is_the_compiled_one_and_both_agree() -> None:
    """The ``levelset`` backend runs WENO5 compiled unless ``engine: numpy``; ENO2 runs NumPy
    whatever the option; both engines give the same T̂."""
    compiled, numpy = _solved({}), _solved({"engine": "numpy"})
    assert compiled.metrics["reachability"]["engine"] == "compiled"
    assert numpy.metrics["reachability"]["engine"] == "numpy"
    assert compiled.t_final == pytest.approx(numpy.t_final, abs=1e-10)
    eno2 = _solved({}, scheme="eno2")
    assert eno2.metrics["reachability"]["engine"] == "numpy"


def test_a_tiny_time_limit_stops_the_run_with_the_status_time_limit() -> None:
    """``max_wall_time`` of a millisecond: the flow-field game ends ``time_limit`` after its first
    level-set step, naming the limit, in far less CPU than the whole solve."""
    start = time.process_time()
    result = _solved({"max_wall_time": 1e-3})
    used = time.process_time() - start
    assert result.status is Status.TIME_LIMIT
    assert "max_wall_time" in result.message and "no capture yet" in result.message
    assert result.metrics["reachability"]["time_steps"] == 1
    assert used < 5.0


def test_the_extremal_march_honours_the_time_limit() -> None:
    data = copy.deepcopy(_spec())
    data["solver"] = {"backend": "extremals", "options": {"extremals": {"max_wall_time": 1e-3}}}
    result = solve(spec_from_dict(data))
    assert result.status is Status.TIME_LIMIT and "extremals" in result.message


def test_progress_lines_off_a_terminal_and_quiet(monkeypatch, capsys) -> None:
    """Off a terminal a plain line per period on stderr (the period set to 0 here), none when
    quiet."""
    monkeypatch.setattr(terminal, "PROGRESS_PERIOD_S", 0.0)
    _solved({})
    lines = [line for line in capsys.readouterr().err.splitlines() if "reachability, levelset" in line]
    assert lines and "level sets, t = " in lines[-1]
    monkeypatch.setattr(terminal, "_settings", {"quiet": True})
    _solved({})
    assert "reachability" not in capsys.readouterr().err
