"""Reachability at the best engine's pace (issue 29, item 4), in a uniform flow whose reachable sets
are exact disks: from the cone ``φ = |x − x₀|`` the set ``{φ ≤ c}`` at time t is the disk of
radius ``c + v̂t`` about ``x₀ + ft``, ``φ = max(|x − x₀ − ft| − v̂t, 0)`` (Hopf–Lax); from the disk
of radius ``c`` the time-to-reach ``T`` solves ``|x − x₀ − fT| = c + v̂T``.

- ``test_level_set_engines``: eq. 5.22 to t = 1 by each level-set engine (WENO5, TVD-RK3, CFL 0.5:
  the same scheme, so the same error), the error the largest ``|φ − φ_exact|`` on the levels
  0.3 … 0.8 above the set; the baseline is the NumPy operator on the whole grid, in the same run.
  Goal: the compiled narrow band (what `engine: auto` runs from 150² nodes, and warm) the fastest
  at that error.
- ``test_level_sets_against_hj_reachability``: the same solve by hj_reachability (JAX, CPU, the
  whole grid; cold = first solve with tracing and XLA compilation, warm = best of the next two).
  Goal: the compiled narrow band at least as fast as hj_reachability warm, in CPU seconds.
- ``test_time_to_reach``: the map ``T`` to 1.5, the error the largest ``|T − T_exact|`` over the
  nodes reached in 0.05 … 1.5. The baseline is issue 29's "today's arrival engine" as the issue
  defines it, measured in the same run: the level-set route (eq. 5.22 from ``|x − x₀| − c`` on the
  whole grid by the NumPy operator, each node's crossing of 0 interpolated in time) at 201². The
  same route on coarser grids gives its cost at each error. Two marching routes
  (:mod:`gamespec.flowfield.marching`): the second-order march alone on 51² … 801², and the
  default, the march corrected by fifth-order differences
  (:mod:`gamespec.flowfield.defect_correction`), on 51² … 401².
  Goal (issue 29): a marching route ≥ 20× faster than the baseline at equal error. Asserted: the
  baseline's CPU over that of the cheapest corrected run at most as far off as the baseline
  (measured in the same run) is at least ``GOAL``. Printed and kept in ``extra_info``: that
  ratio for both routes, at the baseline's error here and at the one issue 29 quotes, and for
  each marching run the ratio at equal error to the cheapest level-set run at most as far off.
  Also asserted: each route's order per halving of dx, at least 1.7 for the march on every step
  (as the tests) and at least 3 for the corrected march on the grids whose error is above 100
  times its tolerance (finer, its default tolerance bounds the error: 5.2e-7 at 201², 2.1e-7 at
  401², where converged it is 1.6e-7 and 5.5e-9).
- ``test_time_to_reach_against_scikit_fmm``: in still air (scikit-fmm's eikonal has no drift),
  scikit-fmm's ``travel_time(order=2)`` beside both routes.

CPU seconds of all threads (``time.process_time``; JAX runs several) and wall seconds, the best of
``ROUNDS`` after one warm-up (Numba's machine code is cached on disk, so warm is what a second
process sees too). ``python -m benchmarks.test_bench_reach`` prints the whole table; under pytest
(``python -m pytest benchmarks/test_bench_reach.py --benchmark-enable -s``) each test prints its
rows and puts the ratios in ``extra_info``. jax, hj_reachability and scikit-fmm are the optional
``bench`` extra (``pip install -e .[bench]``); their tests skip without them.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest
import sympy as sp

from gamespec.flowfield.field import FlowField
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.levelset import BAND_CELLS, LevelSetSolver, initial_cones
from gamespec.flowfield.marching import TOLERANCE, time_to_reach

DRIFT = np.array([0.4, -0.3])
SPEED, ORIGIN, RADIUS = 1.0, np.array([-0.5, 0.3]), 0.5
LOWER, UPPER = (-2.5, -2.5), (2.5, 2.5)
DURATION, LEVELS, T_MAX = 1.0, (0.3, 0.8), 1.5
NODES = (101, 201, 401)
ARRIVAL_NODES = (26, 36, 51, 71, 101, 141, 201)
"""The level-set route to the time-to-reach map on the whole grid to 1.5 (the last is the
baseline's grid; half a minute at 401²): fifth order on this smooth problem, so its coarse grids
meet the marching's error."""
BASELINE_NODES = 201
"""Issue 29's "today's arrival engine": the level-set route at 201² (4.2 s and an error of
1.8e-3 as the issue quotes it, on the machine and with the error of that day)."""
ISSUE_QUOTED_ERROR = 1.8e-3
"""The baseline's error as issue 29 quotes it (not what the route measures here): the ratio at
that error is printed beside the one at the error measured in the run, for the record."""
MARCHING_NODES = (51, 101, 201, 401, 801)
CORRECTED_NODES = (51, 71, 101, 141, 201, 401)
GOAL = 20.0
ROUNDS = 2


@dataclass(frozen=True)
class Row:
    """One line of the table: ``cpu`` and ``wall`` seconds and the error against the exact disks."""

    task: str
    nodes: int
    engine: str
    cpu: float
    wall: float
    error: float

    def line(self, baseline: Row) -> str:
        return (
            f"{self.task:<14} {self.nodes:>4}²  {self.engine:<32} {self.cpu:8.3f} s CPU "
            f"{self.wall:8.3f} s wall  error {self.error:.2e}  "
            f"CPU ratio to the baseline {self.cpu / baseline.cpu:.3f}"
        )


def _grid(n: int) -> Grid:
    return Grid(LOWER, UPPER, (n, n))


def _timed(
    run: Callable[[], np.ndarray], rounds: int = ROUNDS, warmup: bool = True
) -> tuple[np.ndarray, float, float]:
    """``run()``'s value and its best CPU and wall seconds over ``rounds`` (after a warm-up)."""
    if warmup:
        run()
    best, out = (np.inf, np.inf), None
    for _ in range(rounds):
        cpu, wall = time.process_time(), time.perf_counter()
        out = run()
        best = min(best[0], time.process_time() - cpu), min(best[1], time.perf_counter() - wall)
    assert out is not None
    return out, best[0], best[1]


def phi_error(grid: Grid, phi: np.ndarray) -> float:
    """The largest ``|φ − φ_exact|`` on the levels read, ``LEVELS[0] ≤ φ_exact ≤ LEVELS[1]``."""
    exact = np.linalg.norm(grid.points - ORIGIN - DRIFT * DURATION, axis=-1) - SPEED * DURATION
    band = (exact >= LEVELS[0]) & (exact <= LEVELS[1])
    return float(np.abs(phi - exact)[band].max())


def exact_time(grid: Grid, drift: np.ndarray = DRIFT) -> np.ndarray:
    r = grid.points - ORIGIN
    a = SPEED**2 - drift @ drift
    b = r @ drift + RADIUS * SPEED
    return (-b + np.sqrt(b * b + a * ((r * r).sum(-1) - RADIUS**2))) / a


def time_error(grid: Grid, found: np.ndarray, drift: np.ndarray = DRIFT) -> float:
    exact = exact_time(grid, drift)
    mask = (exact > 0.05) & (exact <= T_MAX)
    return float(np.abs(found - exact)[mask].max())


def level_set_run(n: int, engine: str, banded: bool) -> Callable[[], np.ndarray]:
    grid = _grid(n)
    hamiltonian = FlowHamiltonian(np.array([SPEED]), np.broadcast_to(DRIFT, (n, n, 2)))
    solver = LevelSetSolver(grid, hamiltonian, "weno5", 0.5, engine)
    band = LEVELS[1] + BAND_CELLS * float(grid.spacing.max()) if banded else None
    start = initial_cones(grid, ORIGIN[None])
    return lambda: solver.propagate(start, DURATION, band)[0]


def hj_run(n: int) -> Callable[[], np.ndarray]:
    import hj_reachability as hj
    import jax.numpy as jnp
    from gamespec_levelset.hj_solver import drift_dynamics, hj_grid

    x1, x2 = sp.symbols("x1 x2", real=True)
    flow = FlowField((x1, x2), sp.Matrix(DRIFT.tolist()), sp.zeros(2, 2))
    grid = _grid(n)
    nodes = hj_grid(grid)
    dynamics = drift_dynamics(flow, SPEED)
    start = jnp.linalg.norm(nodes.states - jnp.array(ORIGIN), axis=-1)
    settings = hj.SolverSettings.with_accuracy("very_high", CFL_number=0.5)
    times = jnp.array([0.0, DURATION])

    def run() -> np.ndarray:
        values = hj.solve(settings, dynamics, nodes, times, start, progress_bar=False)
        return np.asarray(values[-1].block_until_ready(), dtype=float)

    return run


def arrival_by_level_sets(n: int) -> Callable[[], np.ndarray]:
    """The level-set route to ``T``: eq. 5.22 from ``|x − x₀| − c`` on the whole grid (NumPy
    operator), each node's crossing of 0 linear in time between two steps."""
    grid = _grid(n)
    hamiltonian = FlowHamiltonian(np.array([SPEED]), np.broadcast_to(DRIFT, (n, n, 2)))
    solver = LevelSetSolver(grid, hamiltonian, "weno5", 0.5, "numpy")
    start = (np.linalg.norm(grid.points - ORIGIN, axis=-1) - RADIUS)[None]

    def run() -> np.ndarray:
        phi, t, dt = start, 0.0, solver.max_step
        arrival = np.where(start[0] <= 0, 0.0, np.inf)
        while t < T_MAX + dt:
            new = solver.step(phi, dt)
            crossed = (phi[0] > 0) & (new[0] <= 0)
            arrival[crossed] = t + dt * phi[0][crossed] / (phi[0][crossed] - new[0][crossed])
            phi, t = new, t + dt
        return arrival

    return run


def skfmm_run(n: int) -> Callable[[], np.ndarray]:
    import skfmm

    grid = _grid(n)
    start = np.linalg.norm(grid.points - ORIGIN, axis=-1) - RADIUS
    dx = [float(h) for h in grid.spacing]
    return lambda: np.asarray(skfmm.travel_time(start, np.full(grid.shape, SPEED), dx=dx, order=2))


def level_set_rows(n: int) -> list[Row]:
    grid, rows = _grid(n), []
    for engine, banded, name in (
        ("numpy", False, "numpy, whole grid (baseline)"),
        ("numpy", True, "numpy, narrow band"),
        ("compiled", False, "compiled, whole grid"),
        ("compiled", True, "compiled, narrow band"),
    ):
        phi, cpu, wall = _timed(level_set_run(n, engine, banded))
        rows.append(Row("level sets", n, name, cpu, wall, phi_error(grid, phi)))
    return rows


def hj_rows(n: int) -> list[Row]:
    grid, run = _grid(n), hj_run(n)
    phi, cold_cpu, cold_wall = _timed(run, rounds=1, warmup=False)
    cold = Row("level sets", n, "hj_reachability cold", cold_cpu, cold_wall, phi_error(grid, phi))
    phi, cpu, wall = _timed(run, warmup=False)
    return [cold, Row("level sets", n, "hj_reachability warm", cpu, wall, phi_error(grid, phi))]


def arrival_rows(nodes: tuple[int, ...] = ARRIVAL_NODES) -> list[Row]:
    """The level-set route to ``T`` on each grid (the one on ``BASELINE_NODES`` the baseline)."""
    rows = []
    for n in nodes:
        found, cpu, wall = _timed(arrival_by_level_sets(n), rounds=1)
        name = "level-set arrival" + (" (baseline)" if n == BASELINE_NODES else "")
        rows.append(Row("time to reach", n, name, cpu, wall, time_error(_grid(n), found)))
    return rows


def marching_run(n: int, drift: np.ndarray = DRIFT, order: int = 5) -> Callable[[], np.ndarray]:
    grid = _grid(n)
    tabulated = np.broadcast_to(drift, (n, n, 2))
    return lambda: time_to_reach(grid, tabulated, SPEED, ORIGIN, RADIUS, t_max=T_MAX + 0.1, order=order)


ROUTES = {2: "fast marching, order 2", 5: "marching + fifth-order correction"}
"""The name of each ``order`` of :func:`~gamespec.flowfield.marching.time_to_reach` in the table."""


def marching_rows(order: int, nodes: tuple[int, ...]) -> list[Row]:
    rows = []
    for n in nodes:
        found, cpu, wall = _timed(marching_run(n, order=order))
        rows.append(Row("time to reach", n, ROUTES[order], cpu, wall, time_error(_grid(n), found)))
    return rows


def at_equal_error(marching: Row, arrivals: list[Row]) -> float | None:
    """The CPU ratio of the cheapest level-set run at most as far off as ``marching`` to it (None
    when no level-set grid measured is that coarse)."""
    matching = [row.cpu for row in arrivals if row.error <= marching.error]
    return min(matching) / marching.cpu if matching else None


def against_baseline(baseline: Row, marching: list[Row], error: float) -> tuple[Row | None, float | None]:
    """The cheapest marching run at most ``error`` off and the baseline's CPU over its (Nones
    when no marching grid measured is that fine)."""
    matching = [row for row in marching if row.error <= error]
    if not matching:
        return None, None
    cheapest = min(matching, key=lambda row: row.cpu)
    return cheapest, baseline.cpu / cheapest.cpu


def measured_orders(rows: list[Row]) -> np.ndarray:
    """The order between successive grids, ``log(e₁/e₂) / log(dx₁/dx₂)`` (``n`` nodes: ``n − 1``
    cells)."""
    errors = np.array([row.error for row in rows])
    cells = np.array([row.nodes - 1 for row in rows], dtype=float)
    return np.log(errors[:-1] / errors[1:]) / np.log(cells[1:] / cells[:-1])


def nodes_for(rows: list[Row], error: float) -> int:
    """The grid at which the finest run's error would fall to ``error`` at the last measured order
    (an extrapolation, printed as such)."""
    order = float(measured_orders(rows)[-1])
    return int(np.ceil((rows[-1].nodes - 1) * (rows[-1].error / error) ** (1 / order))) + 1


def still_air_rows(n: int) -> list[Row]:
    grid, still = _grid(n), np.zeros(2)
    rows = []
    for order, name in ROUTES.items():
        found, cpu, wall = _timed(marching_run(n, still, order))
        rows.append(Row("still air", n, name, cpu, wall, time_error(grid, found, still)))
    found, cpu, wall = _timed(skfmm_run(n))
    theirs = Row("still air", n, "scikit-fmm travel_time, order 2", cpu, wall, time_error(grid, found, still))
    return [*rows, theirs]


def _report(benchmark: Any, rows: list[Row], baseline: Row) -> None:
    for row in rows:
        print(row.line(baseline))
        name = f"{row.engine} at {row.nodes}²"
        benchmark.extra_info[f"{name} cpu_s"] = row.cpu
        benchmark.extra_info[f"{name} error"] = row.error
        benchmark.extra_info[f"{name} over baseline"] = row.cpu / baseline.cpu


@pytest.mark.parametrize("n", NODES)
def test_level_set_engines(benchmark, n: int) -> None:
    benchmark.group = f"level sets, uniform flow, {n}²"
    rows = benchmark.pedantic(level_set_rows, args=(n,), rounds=1, warmup_rounds=0)
    _report(benchmark, rows, rows[0])
    errors = np.array([row.error for row in rows])
    assert np.ptp(errors) < 1e-3 * errors.max()  # the same scheme: the same error
    compiled_band = rows[-1]
    assert compiled_band.cpu == min(row.cpu for row in rows)


@pytest.mark.parametrize("n", NODES)
def test_level_sets_against_hj_reachability(benchmark, n: int) -> None:
    pytest.importorskip("hj_reachability")
    benchmark.group = f"level sets, uniform flow, {n}², against hj_reachability"
    hj = benchmark.pedantic(hj_rows, args=(n,), rounds=1, warmup_rounds=0)
    compiled_band = level_set_rows(n)[-1]
    _report(benchmark, [compiled_band, *hj], hj[-1])
    # at least as accurate (JAX runs float32: its error stops near 1.6e-5 at 401², ours is 2.2e-8)
    assert compiled_band.error <= 1.05 * hj[-1].error
    assert compiled_band.cpu <= hj[-1].cpu


def time_to_reach_report(arrivals: list[Row], routes: dict[int, list[Row]]) -> dict[str, Any]:
    """Print the ratios of ``test_time_to_reach`` and return them by name."""
    baseline = next(row for row in arrivals if row.nodes == BASELINE_NODES)
    ratios: dict[str, Any] = {}
    for order, rows in routes.items():
        name = ROUTES[order]
        orders = measured_orders(rows)
        print(f"{name}: measured order per halving of dx " + ", ".join(f"{p:.2f}" for p in orders))
        ratios[f"{name}: measured orders"] = orders.tolist()
        for error, what in ((baseline.error, "measured here"), (ISSUE_QUOTED_ERROR, "as issue 29 quotes it")):
            row, ratio = against_baseline(baseline, rows, error)
            ratios[f"{name}: baseline over it at the baseline's error {what}"] = ratio
            if row is None:
                print(
                    f"the baseline's error {what} ({error:.2e}): no {name} grid measured is as accurate "
                    f"(≈ {nodes_for(rows, error)}² at the last measured order)"
                )
            else:
                print(f"the baseline's error {what} ({error:.2e}): {name} at {row.nodes}², {ratio:.1f}×")
        for row in rows:
            ratio = at_equal_error(row, arrivals)
            ratios[f"{name} at {row.nodes}²: level sets at equal error over it"] = ratio
            shown = "no level-set grid that coarse" if ratio is None else f"{ratio:.2f}×"
            print(f"{name} at {row.nodes}² (error {row.error:.2e}): level sets at equal error / it {shown}")
    met = ratios[f"{ROUTES[5]}: baseline over it at the baseline's error measured here"]
    ratios["goal met"] = met is not None and met >= GOAL
    print(
        f"issue 29's goal ({GOAL:.0f}× the baseline at its error, measured in this run): "
        + ("met" if ratios["goal met"] else "not met")
    )
    return ratios


def time_to_reach_routes() -> dict[int, list[Row]]:
    return {2: marching_rows(2, MARCHING_NODES), 5: marching_rows(5, CORRECTED_NODES)}


def test_time_to_reach(benchmark) -> None:
    """The baseline (the level-set route at 201²), the same route on coarser grids, the march and
    the corrected march; the ratios at equal error printed and kept (module doc); the goal and
    each route's order asserted."""
    benchmark.group = "time-to-reach map, uniform flow"
    arrivals = benchmark.pedantic(arrival_rows, rounds=1, warmup_rounds=0)
    routes = time_to_reach_routes()
    baseline = next(row for row in arrivals if row.nodes == BASELINE_NODES)
    _report(benchmark, [*arrivals, *routes[2], *routes[5]], baseline)
    ratios = time_to_reach_report(arrivals, routes)
    for name, value in ratios.items():
        benchmark.extra_info[name] = value
    assert np.all(measured_orders(routes[2]) >= 1.7)
    coarse = [row for row in routes[5] if row.error > 100 * TOLERANCE]  # not yet iteration-bound
    assert np.all(measured_orders(coarse) >= 3.0)
    assert ratios["goal met"]


@pytest.mark.parametrize("n", NODES)
def test_time_to_reach_against_scikit_fmm(benchmark, n: int) -> None:
    pytest.importorskip("skfmm")
    benchmark.group = f"time-to-reach map, still air, {n}²"
    rows = benchmark.pedantic(still_air_rows, args=(n,), rounds=1, warmup_rounds=0)
    _report(benchmark, rows, rows[-1])


def main() -> None:
    """Print the whole table (the optional engines where installed)."""
    for n in NODES:
        rows = level_set_rows(n)
        try:
            rows += hj_rows(n)
        except ImportError as err:
            print(f"hj_reachability not installed ({err})")
        for row in rows:
            print(row.line(rows[0]))
    arrivals = arrival_rows()
    routes = time_to_reach_routes()
    baseline = next(row for row in arrivals if row.nodes == BASELINE_NODES)
    for row in [*arrivals, *routes[2], *routes[5]]:
        print(row.line(baseline))
    time_to_reach_report(arrivals, routes)
    for n in NODES:
        try:
            rows = still_air_rows(n)
        except ImportError as err:
            print(f"scikit-fmm not installed ({err})")
            break
        for row in rows:
            print(row.line(rows[-1]))


if __name__ == "__main__":
    main()
