"""Stage 1 of chapter 5 (section 5.2): the ``flow_reachability`` model of the ``levelset``,
``extremals`` and ``hj_reachability`` backends.

``levelset`` solves eq. 5.22 on the grid (:mod:`gamespec.flowfield.levelset`) and integrates the
nominal paths backward along ∇φ (eqs. 5.23–5.26); ``extremals`` shoots the characteristics
(:mod:`gamespec.flowfield.extremals`) and takes the extremals through ``x_f`` as the nominal paths;
``hj_reachability`` is the level-set step compiled by JAX. The Result holds ``T̂`` (``t_final``,
``metrics.capture_time``), ``x_f``, the nominal paths (arrays ``nominal_time``,
``nominal_positions``, ``nominal_directions``), the closure errors, the other method's ``T̂`` as a
cross-check and, for the NumPy level sets, the grid-error estimate with its check. The model keeps
its last Result for the values that determine it
(:func:`gamespec.flowfield.stages.reachability_key`), so a re-solve with new values of parameters
that enter only the game (α) recomputes nothing, the cross-check included.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from gamespec.compiling import CompiledModel, Inputs, refuse_inputs
from gamespec.flowfield.budget import UNLIMITED, Budget
from gamespec.flowfield.covariance_game import PLAYERS
from gamespec.flowfield.extremals import capture_by_extremals
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.levelset import (
    LevelSetSolver,
    capture_by_level_sets,
    choose_engine,
    coarser_grid,
    grid_error_estimate,
)
from gamespec.flowfield.nominal import NominalPaths, from_extremals, from_level_sets
from gamespec.flowfield.problem import FlowGameData, evaluate
from gamespec.flowfield.spec import FlowReachabilitySpec
from gamespec.flowfield.stages import reachability_key
from gamespec.result import Result, Status
from gamespec.terminal import progress
from gamespec_levelset.options import FlowGameOptions
from gamespec_levelset.verdicts import verdicts

GRID_ERROR_STEPS = 0.05
"""The tolerance of ``checks.capture_time_grid_error``, in game steps ``T̂/N``: the level-set grid
may move the game's time grid by at most 5 % of a step."""


@dataclass(frozen=True)
class Reachability:
    """Stage 1's outcome: ``T̂``, ``x_f`` and the nominal paths, or why there are none; the arrays
    and metrics it contributes to the Result; the grid-error estimate where one was made (None
    inside: the coarser grid found no capture); ``timed_out``: the time limit stopped it."""

    capture_time: float | None
    capture_point: np.ndarray | None
    paths: NominalPaths | None
    message: str
    arrays: dict[str, np.ndarray]
    metrics: dict[str, Any]
    grid_error: dict[str, Any] | None = None
    timed_out: bool = False


def _level_set_reach(
    spec: FlowReachabilitySpec,
    data: FlowGameData,
    nominal: bool = True,
    engine: str = "auto",
    budget: Budget = UNLIMITED,
) -> Reachability:
    """Stage 1 by level sets; with ``nominal`` (not a cross-check) also the nominal paths and, for
    the project's engines (``auto``, ``compiled``, ``numpy``; not ``jax``), the grid-error estimate from the
    same levels on a coarser grid (:func:`~gamespec.flowfield.levelset.grid_error_estimate`, about
    1/8 of the work), both grids by the engine :func:`~gamespec.flowfield.levelset.choose_engine`
    picks for the fine one. ``budget``: the time limit over both searches and the progress line."""
    m = spec.method
    speeds = data.nominal_speeds

    def own_solver(grid: Grid) -> LevelSetSolver:
        hamiltonian = FlowHamiltonian(speeds, data.field.drift(grid.points))
        return LevelSetSolver(grid, hamiltonian, m.scheme, m.cfl, choose_engine(engine, data.grid))

    if engine == "jax":
        from gamespec_levelset.hj_solver import HJSolver

        solver = HJSolver(data.grid, data.field, speeds, m.cfl)
        name = "hj_reachability (jax)"
    else:
        solver = own_solver(data.grid)
        name = "compiled" if solver.compiled else "numpy"
    reach = capture_by_level_sets(solver, data.origins, m.max_time, levels=m.read_levels, budget=budget)
    metrics = {
        "method": "levelset",
        "engine": name,
        "scheme": "weno5" if engine == "jax" else m.scheme,
        "nodes": list(data.grid.shape),
        "time_steps": reach.steps,
        "band_level": reach.band,
    }
    arrays = {"reach_margin_time": reach.times, "reach_margin": reach.margins}
    if reach.capture_time is None:
        return Reachability(None, None, None, reach.message, arrays, metrics, timed_out=reach.timed_out)
    paths = from_level_sets(reach, data.field, speeds, data.origins) if nominal else None
    grid_error = None
    if nominal and engine != "jax":
        coarse_solver = own_solver(coarser_grid(data.grid))
        coarse = capture_by_level_sets(
            coarse_solver, data.origins, m.max_time, levels=m.read_levels, budget=budget
        )
        if coarse.timed_out:
            return Reachability(None, None, None, coarse.message, arrays, metrics, timed_out=True)
        grid_error = {"estimate": grid_error_estimate(reach, coarse)}
    metrics |= {
        "levels": reach.levels.tolist(),
        "level_capture_times": reach.level_times.tolist(),
        "level_offset": float(reach.level_times[1] - reach.level_times[0]),
    }
    arrays |= {
        "grid_x": data.grid.axes[0],
        "grid_y": data.grid.axes[1],
        "phi_final": reach.snapshots[-1].astype(float),
    }
    return Reachability(reach.capture_time, reach.capture_point, paths, "", arrays, metrics, grid_error)


def _extremal_reach(
    spec: FlowReachabilitySpec, data: FlowGameData, nominal: bool = True, budget: Budget = UNLIMITED
) -> Reachability:
    e = spec.method.extremals
    speeds = data.nominal_speeds
    reach = capture_by_extremals(
        data.field,
        data.origins,
        speeds,
        spec.method.max_time,
        directions=e.directions,
        dt=e.step,
        budget=budget,
    )
    metrics = {"method": "extremals", "directions": e.directions, "time_step": e.step}
    if reach.timed_out:
        message = budget.message(f"extremals at t = {reach.times[-1]:.4g}, no capture yet")
        return Reachability(None, None, None, message, {}, metrics, timed_out=True)
    if reach.capture_time is None:
        return Reachability(
            None, None, None, f"no capture before t_max = {spec.method.max_time:g}", {}, metrics
        )
    paths = (
        from_extremals(data.field, data.origins, speeds, reach.capture_time, reach.capture_point)
        if nominal
        else None
    )
    arrays = {"front_final": reach.fronts[-1]}
    return Reachability(reach.capture_time, reach.capture_point, paths, "", arrays, metrics)


def _differences(reach: Reachability, other: Reachability | None) -> dict[str, float | None]:
    """The cross-check's values: the other method's ``T̂`` and both differences."""
    if other is None:
        return {}
    if other.capture_time is None:
        return {"capture_time_other_method": None}
    return {
        "capture_time_other_method": other.capture_time,
        "capture_time_difference": abs(other.capture_time - reach.capture_time),
        "capture_point_difference": float(np.linalg.norm(other.capture_point - reach.capture_point)),
    }


REACHABILITY: dict[str, Callable[[FlowReachabilitySpec, FlowGameData, str, Budget], Reachability]] = {
    "levelset": lambda spec, data, engine, budget: _level_set_reach(spec, data, engine=engine, budget=budget),
    "extremals": lambda spec, data, engine, budget: _extremal_reach(spec, data, budget=budget),
    "hj_reachability": lambda spec, data, engine, budget: _level_set_reach(
        spec, data, engine="jax", budget=budget
    ),
}
"""Stage 1 by each backend's method, from the spec, its values, the levelset engine and the budget."""


class ReachabilityModel(CompiledModel):
    """Stage 1 for one ``flow_reachability`` spec by ``method`` (a key of :data:`REACHABILITY`) with
    the backend's ``options``: ``cross_check`` also runs the other method and reports the
    difference of ``T̂``; ``max_wall_time`` bounds the whole stage (status ``time_limit``), which
    shows its progress on stderr (:mod:`gamespec.terminal`); ``engine`` is the level sets' step.
    The last Result is kept for its :func:`~gamespec.flowfield.stages.reachability_key` and
    returned again (with the new parameter values) while the key stays the same."""

    def __init__(self, spec: FlowReachabilitySpec, method: str, options: FlowGameOptions) -> None:
        self.spec, self.method, self.options = spec, method, options
        self._solved: tuple[tuple, Result] | None = None

    def _cross_check(self, data: FlowGameData, budget: Budget) -> Reachability | None:
        """The other method's reachability (None without a cross-check)."""
        if not self.options.cross_check:
            return None
        if self.method != "extremals":
            return _extremal_reach(self.spec, data, nominal=False, budget=budget)
        return _level_set_reach(self.spec, data, nominal=False, engine=self.options.engine, budget=budget)

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        refuse_inputs(inputs, self.spec.kind)
        start = time.perf_counter()
        values = {**self.spec.problem.parameters, **(parameters or {})}
        data = evaluate(self.spec, values)
        key = reachability_key(data)
        if self._solved is None or self._solved[0] != key:
            self._solved = key, self._reached(data)
        return self._solved[1].model_copy(
            update={"parameters": values, "solve_time_s": time.perf_counter() - start}
        )

    def _reached(self, data: FlowGameData) -> Result:
        """Stage 1's Result for ``data``: the reachability, the nominal paths and the checks; the
        status ``time_limit`` when the limit stopped it (the search or the cross-check)."""
        with progress(f"{self.spec.name} (reachability, {self.method})") as tracker:
            budget = Budget(self.options.max_wall_time, tracker)
            reach = REACHABILITY[self.method](self.spec, data, self.options.engine, budget)
            other = None if reach.capture_time is None else self._cross_check(data, budget)
        stopped = other if other is not None and other.timed_out else reach
        if reach.capture_time is None or stopped.timed_out:
            return Result(
                status=Status.TIME_LIMIT if stopped.timed_out else Status.INFEASIBLE,
                message=stopped.message,
                arrays=reach.arrays,
                metrics={"reachability": reach.metrics},
            )
        graded: dict[str, tuple[float | None, float]] = {}
        metrics: dict[str, Any] = {
            "capture_time": reach.capture_time,
            "capture_point": [float(v) for v in reach.capture_point],
            "reachability": reach.metrics,
        }
        if reach.grid_error is not None:
            estimate = reach.grid_error["estimate"]
            value = None if estimate is None else estimate["capture_time"]
            graded["capture_time_grid_error"] = (value, GRID_ERROR_STEPS * data.step)
            metrics["grid_error_estimate"] = estimate
        checks = _differences(reach, other)
        checks |= {
            f"closure_error_{n}": float(e) for n, e in zip(PLAYERS, reach.paths.closure_error, strict=True)
        }
        checks |= {name: value for name, (value, _) in graded.items()}
        if graded:
            metrics |= verdicts(graded)
        paths = reach.paths
        return Result(
            status=Status.OPTIMAL,
            objective=reach.capture_time,
            t_final=reach.capture_time,
            arrays={
                **reach.arrays,
                "nominal_time": paths.times,
                "nominal_positions": paths.positions,
                "nominal_directions": paths.directions,
            },
            metrics=metrics,
            checks=checks,
        )
