"""The compiled level-set step (:mod:`gamespec.flowfield.compiled`) against the NumPy operator and
the exact disks of a uniform flow; the engine a solve uses; the reachability stage's time limit
and progress line (:mod:`gamespec.flowfield.budget`)."""

from __future__ import annotations

import copy
import sys
import time

import numpy as np
import pytest

from gamespec import terminal
from gamespec.flowfield import compiled
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.levelset import COMPILED_NODES, LevelSetSolver, choose_engine, initial_cones
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


def test_auto_compiles_from_the_break_even_grid_or_once_loaded(monkeypatch) -> None:
    """``auto``: NumPy on a small grid in a process without the compiled step (loading Numba
    would cost more than it saves), compiled from :data:`COMPILED_NODES` nodes or once loaded."""
    small, large = Grid((0.0, 0.0), (1.0, 1.0), (101, 101)), Grid((0.0, 0.0), (1.0, 1.0), (151, 151))
    assert large.shape[0] * large.shape[1] >= COMPILED_NODES > small.shape[0] * small.shape[1]
    monkeypatch.delitem(sys.modules, "gamespec.flowfield.compiled", raising=False)
    assert choose_engine("auto", small) == "numpy" and choose_engine("auto", large) == "compiled"
    assert choose_engine("compiled", small) == "compiled" and choose_engine("numpy", large) == "numpy"
    monkeypatch.setitem(sys.modules, "gamespec.flowfield.compiled", compiled)
    assert choose_engine("auto", small) == "compiled"


def test_both_engines_give_the_same_capture_and_eno2_runs_numpy() -> None:
    """The ``levelset`` backend reports the engine it ran; ENO2 runs NumPy whatever the option."""
    fast, numpy = _solved({"engine": "compiled"}), _solved({"engine": "numpy"})
    assert fast.metrics["reachability"]["engine"] == "compiled"
    assert numpy.metrics["reachability"]["engine"] == "numpy"
    assert fast.t_final == pytest.approx(numpy.t_final, abs=1e-10)
    eno2 = _solved({"engine": "compiled"}, scheme="eno2")
    assert eno2.metrics["reachability"]["engine"] == "numpy"


def test_a_tiny_time_limit_stops_the_run_with_the_status_time_limit() -> None:
    """``max_wall_time`` of a millisecond: the flow-field game ends ``time_limit`` within the first
    few level-set steps (the limit is checked after each; the capture takes dozens), naming the
    limit, in a fraction of the CPU of the whole solve."""
    start = time.process_time()
    result = _solved({"max_wall_time": 1e-3})
    used = time.process_time() - start
    assert result.status is Status.TIME_LIMIT
    assert "max_wall_time" in result.message and "no capture yet" in result.message
    assert 1 <= result.metrics["reachability"]["time_steps"] <= 5
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
