"""Chapter 5 timings: the level-set solve of eq. 5.22 on the Hurricane Hugo field (eqs. 5.40–5.42)
at two grid sizes, beside hj_reachability (JAX, CPU; WENO5 + TVD-RK3, the same scheme) where it is
installed — the goal is "not slower" — with the largest difference of the two solutions on the
front's band; one Gauss–Seidel sweep of the covariance game (Algorithm 3) on the linear-flow file,
as a ratio to one pursuer step in the same run; and the peak memory of the capture search on the
finest grid (tracemalloc's peak and the process's maximum resident set, ``extra_info``).

Run: ``python -m pytest benchmarks/test_bench_flowfield.py --benchmark-enable``.
hj_reachability is optional (``pip install hj-reachability jax``); its tests skip without it.
"""

from __future__ import annotations

import resource
import time
import tracemalloc
from dataclasses import replace

import numpy as np
import pytest

import gamespec
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.levelset import LevelSetSolver, capture_by_level_sets, initial_cones
from gamespec.flowfield.problem import evaluate
from tests.conftest import PROBLEMS

HUGO = PROBLEMS / "ch5" / "hurricane_hugo.yaml"
LINEAR = PROBLEMS / "ch5" / "linear_flow.yaml"
NODES = (101, 201)
DURATION = 1.5


def _hugo(n: int):
    data = evaluate(gamespec.load(HUGO))
    grid = Grid(data.grid.lower, data.grid.upper, (n, n))
    return data, grid


def _ours(n: int) -> np.ndarray:
    data, grid = _hugo(n)
    solver = LevelSetSolver(
        grid, FlowHamiltonian(data.nominal_speeds[:1], data.field.drift(grid.points)), "weno5"
    )
    return solver.propagate(initial_cones(grid, data.origins[:1]), DURATION)[0]


@pytest.mark.parametrize("n", NODES)
def test_levelset_hugo(benchmark, n: int) -> None:
    benchmark.group = f"ch5 level set, Hugo field, {n}×{n}, t = {DURATION}"
    phi = benchmark.pedantic(_ours, args=(n,), rounds=3, warmup_rounds=0)
    assert np.isfinite(phi).all()


def _hj_solver(n: int):
    pytest.importorskip("hj_reachability")
    import hj_reachability as hj
    import jax.numpy as jnp
    from gamespec_levelset.hj_solver import drift_dynamics, hj_grid

    data, grid = _hugo(n)
    dynamics = drift_dynamics(data.field, float(data.nominal_speeds[0]))
    nodes = hj_grid(grid)
    initial = jnp.linalg.norm(nodes.states - jnp.array(data.origins[0]), axis=-1)
    settings = hj.SolverSettings.with_accuracy("very_high", CFL_number=0.5)

    def run() -> np.ndarray:
        values = hj.solve(settings, dynamics, nodes, jnp.array([0.0, DURATION]), initial, progress_bar=False)
        return np.asarray(values[-1].block_until_ready())

    return run


@pytest.mark.parametrize("n", NODES)
def test_hj_reachability_hugo(benchmark, n: int) -> None:
    benchmark.group = f"ch5 level set, Hugo field, {n}×{n}, t = {DURATION}"
    run = _hj_solver(n)
    phi = benchmark.pedantic(run, rounds=3, warmup_rounds=1)
    ours = _ours(n)
    band = (ours > 0.3) & (ours < 1.5)
    difference = float(np.abs(phi - ours)[band].max())
    benchmark.extra_info["max_difference_on_band"] = difference
    assert difference < 5 * (25 / (n - 1)) ** 2


def _linear_game(feedforward: str):
    """The linear-flow file's covariance game and its Gauss–Seidel players."""
    from gamespec_levelset.backend import FlowGameModel, FlowGameOptions, game_players, linearized_game

    spec = gamespec.load(LINEAR, [f"problem.feedforward={feedforward}", "method.game.scheme=gauss_seidel"])
    options = FlowGameOptions(cross_check=False)
    data = evaluate(spec)
    game = linearized_game(data, FlowGameModel(spec, options, "levelset").reachability(data)).game
    return game, game_players(spec, options, game)


def _cpu(run, rounds: int = 3) -> float:
    start = time.process_time()
    for _ in range(rounds):
        run()
    return (time.process_time() - start) / rounds


@pytest.mark.parametrize("feedforward", ["nominal", "free"])
def test_gauss_seidel_iteration(benchmark, feedforward: str) -> None:
    """The first Gauss–Seidel sweep of Algorithm 3 on the linear-flow file's game, from open loop
    (the pursuer's conic step, then the evader's convex–concave procedure from zero gains, the
    costliest sweep; the conic problems already compiled), against a baseline measured in the same
    run: one solve of the pursuer's conic step. Goal: with ``V = Û`` the sweep costs at most 3
    pursuer steps (the evader's tangent steps are closed-form); with ``V`` free each tangent step
    is a conic solve. ``extra_info``: the ratio, in CPU time."""
    from gamespec.best_response import iterate

    benchmark.group = "ch5 covariance game, one Gauss–Seidel sweep"
    game, cast = _linear_game(feedforward)
    start = dict(zip(("pursuer", "evader"), game.nominal(), strict=True))
    once = replace(cast.settings, max_iterations=1)
    cast.pursuer.respond(start["evader"])  # CVXPY compiles the problem on its first solve
    baseline = _cpu(lambda: cast.pursuer.respond(start["evader"]))

    def sweep() -> int:
        cast.evader.current = start["evader"]
        return iterate(cast.players, start, once).iterations

    assert benchmark.pedantic(sweep, rounds=3, warmup_rounds=0) == 1
    benchmark.extra_info["sweep_over_pursuer_step"] = _cpu(sweep) / baseline
    if feedforward == "nominal":
        assert benchmark.extra_info["sweep_over_pursuer_step"] < 3


def test_capture_search_memory_at_the_finest_grid(benchmark) -> None:
    data, grid = _hugo(NODES[-1])
    solver = LevelSetSolver(
        grid, FlowHamiltonian(data.nominal_speeds, data.field.drift(grid.points)), "weno5"
    )
    tracemalloc.start()
    reach = benchmark.pedantic(
        capture_by_level_sets, args=(solver, data.origins, 10.0), rounds=1, warmup_rounds=0
    )
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    benchmark.extra_info["peak_memory_mib"] = peak / 2**20
    benchmark.extra_info["max_rss_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**10
    benchmark.extra_info["snapshots"] = len(reach.snapshot_times)
    assert reach.capture_time is not None
