"""Grid-convergence table of the level-set capture time and point (chapter 5) against extremal
shooting, for the shipped linear-flow and Hurricane Hugo files.

Run: ``python -m benchmarks.flowfield_grid_convergence [--finest N]`` (minutes; not part of the
test suite). The reference is extremal shooting with 1440 directions and RK4 step 1e-3, whose own
change from 720 directions / step 2e-3 is printed as its error estimate.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from gamespec.flowfield.extremals import capture_by_extremals
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.levelset import LevelSetSolver, capture_by_level_sets
from gamespec.flowfield.problem import evaluate
from gamespec.loader import load

FILES = ("problems/ch5/linear_flow.yaml", "problems/ch5/hurricane_hugo.yaml")


def table(path: str, scale: list[float]) -> list[str]:
    spec = load(Path(path))
    data = evaluate(spec)
    speeds = data.nominal_speeds
    fine = capture_by_extremals(
        data.field, data.origins, speeds, spec.method.max_time, directions=1440, dt=1e-3
    )
    coarse = capture_by_extremals(
        data.field, data.origins, speeds, spec.method.max_time, directions=720, dt=2e-3
    )
    point = np.round(fine.capture_point, 4).tolist()
    rows = [
        f"### {spec.name}: reference T̂ = {fine.capture_time:.6f}, x_f = {point}"
        f" (720 directions differ by {abs(coarse.capture_time - fine.capture_time):.1e})",
        "",
        "| nodes | dx | T̂ (level set) | |ΔT̂| | |ΔT(c₁)| | |Δx_f| | time steps | seconds |",
        "|---|---|---|---|---|---|---|---|",
    ]
    nodes = np.array(data.grid.shape)
    for s in scale:
        shape = tuple(round((n - 1) * s) + 1 for n in nodes)
        grid = Grid(data.grid.lower, data.grid.upper, shape)
        solver = LevelSetSolver(
            grid, FlowHamiltonian(speeds, data.field.drift(grid.points)), spec.method.scheme
        )
        start = time.perf_counter()
        reach = capture_by_level_sets(
            solver, data.origins, spec.method.max_time, levels=spec.method.read_levels
        )
        seconds = time.perf_counter() - start
        if reach.capture_time is None:
            rows.append(f"| {shape[0]}×{shape[1]} | {grid.spacing.max():.4f} | {reach.message} | | | | | |")
            continue
        rows.append(
            f"| {shape[0]}×{shape[1]} | {grid.spacing.max():.4f} | {reach.capture_time:.6f} | "
            f"{abs(reach.capture_time - fine.capture_time):.2e} | "
            f"{abs(reach.level_times[0] - fine.capture_time):.2e} | "
            f"{np.linalg.norm(reach.capture_point - fine.capture_point):.2e} | "
            f"{reach.steps} | {seconds:.1f} |"
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--finest", type=float, default=2.0, help="largest refinement of the file's grid")
    args = parser.parse_args()
    scales = [0.5, 1.0] + ([args.finest] if args.finest > 1 else [])
    for path in FILES:
        print("\n".join(table(path, scales)) + "\n")


if __name__ == "__main__":
    main()
