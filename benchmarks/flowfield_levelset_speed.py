"""The level-set capture search on the Hurricane Hugo field (eqs. 5.20–5.22, 5.40–5.42) by the NumPy
engine and by hj_reachability (JAX, CPU), each against a converged extremal-shooting reference.

Run: ``python benchmarks/flowfield_levelset_speed.py [--nodes 101 201] [--directions 2880]``
(minutes; not part of the test suite). Each engine runs in a fresh process per grid: ``cold`` is
its first solve there (for JAX: tracing and XLA compilation included, as one ``gamespec solve``
sees it, not the import of jax), ``warm`` the best of the two that follow. Seconds are CPU seconds of
all threads (``time.process_time``) and wall seconds. The reference is extremal shooting with
``--directions`` directions and RK4 step 1e-3; its change from half as many directions is printed
as its own error.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import gamespec
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.levelset import LevelSetReach, LevelSetSolver, capture_by_level_sets
from gamespec.flowfield.problem import evaluate

HUGO = Path(__file__).resolve().parents[1] / "problems" / "ch5" / "hurricane_hugo.yaml"


def capture(n: int, engine: str = "numpy") -> LevelSetReach:
    """The capture search on the Hugo file at n × n nodes, the file's scheme and CFL number."""
    spec = gamespec.load(HUGO)
    data, m = evaluate(spec), spec.method
    grid = Grid(data.grid.lower, data.grid.upper, (n, n))
    if engine == "jax":
        from gamespec_levelset.hj_solver import HJSolver

        solver = HJSolver(grid, data.field, data.nominal_speeds, m.cfl)
    else:
        hamiltonian = FlowHamiltonian(data.nominal_speeds, data.field.drift(grid.points))
        solver = LevelSetSolver(grid, hamiltonian, m.scheme, m.cfl)
    return capture_by_level_sets(solver, data.origins, m.max_time, levels=m.read_levels)


def timed(run: Callable[[], LevelSetReach]) -> tuple[LevelSetReach, float, float]:
    """``run()`` and its CPU (all threads) and wall seconds."""
    cpu, wall = time.process_time(), time.perf_counter()
    out = run()
    return out, time.process_time() - cpu, time.perf_counter() - wall


def _worker(engine: str, n: int) -> dict:
    if engine == "jax":
        import hj_reachability  # noqa: F401  (imported before the clock starts)
    runs = [timed(lambda: capture(n, engine)) for _ in range(3)]
    reach = runs[0][0]
    if reach.capture_time is None:
        raise SystemExit(reach.message)
    return {
        "capture_time": reach.capture_time,
        "capture_point": [float(v) for v in reach.capture_point],
        "steps": reach.steps,
        "cold": runs[0][1:],
        "warm": [min(r[1] for r in runs[1:]), min(r[2] for r in runs[1:])],
    }


def _spawn(engine: str, n: int) -> dict | None:
    done = subprocess.run(
        [sys.executable, __file__, "--worker", engine, str(n)], capture_output=True, text=True, check=False
    )
    if done.returncode:
        print(f"{engine} at {n}: {done.stderr.strip().splitlines()[-1]}", file=sys.stderr)
        return None
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--nodes", type=int, nargs="+", default=[101, 201])
    parser.add_argument("--directions", type=int, default=2880)
    parser.add_argument("--worker", nargs=2, metavar=("ENGINE", "N"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(_worker(args.worker[0], int(args.worker[1]))))
        return
    from gamespec.flowfield.extremals import capture_by_extremals

    data = evaluate(gamespec.load(HUGO))
    ref, half = (
        capture_by_extremals(data.field, data.origins, data.nominal_speeds, 10.0, directions=d, dt=1e-3)
        for d in (args.directions, args.directions // 2)
    )
    print(
        f"reference T̂ = {ref.capture_time:.7f}, x_f = {np.round(ref.capture_point, 5).tolist()} "
        f"({args.directions // 2} directions differ by {abs(half.capture_time - ref.capture_time):.1e} "
        f"in T̂, {np.linalg.norm(half.capture_point - ref.capture_point):.1e} in x_f)\n"
    )
    print(
        "| grid | engine | steps | T̂ | abs T̂ error | x_f error | cold s (CPU / wall) | warm s (CPU / wall) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for n in args.nodes:
        for engine in ("numpy", "jax"):
            row = _spawn(engine, n)
            if row is None:
                continue
            error = np.linalg.norm(np.array(row["capture_point"]) - ref.capture_point)
            cold, warm = (f"{c:.2f} / {w:.2f}" for c, w in (row["cold"], row["warm"]))
            print(
                f"| {n}² | {engine} | {row['steps']} | {row['capture_time']:.7f} | "
                f"{abs(row['capture_time'] - ref.capture_time):.2e} | {error:.2e} | {cold} | {warm} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
