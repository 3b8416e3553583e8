"""Grid-refinement table of the homicidal chauffeur's barrier threshold on the ``hji`` backend.

Isaacs' barrier closes around the capture circle iff ℓ/R < √(1−γ²) + γ·asin γ − 1 (0.2569 at
γ = 0.7). Just above it the two barrier arcs leave a gap 2(ℓ − ℓ*) wide on the car's axis at
y = γR (where the car's turning just matches the pedestrian's sideways run), and the captured set
leaks through it; below it the set stops growing (``metrics.capture_region.converged``). The study
bisects ℓ on that verdict (:func:`switch_bracket`) for boxes and grids given on the command line.

What the table shows (measured for issue 26; the table is in ``docs/feedback-equilibria.md``): the
switch does not depend on the box (by Lax–Friedrichs, the value at the gap point is the same to 1e-4
on [−1, 1]², [−1.5, 1.5]² and [−3, 3]² at one spacing) but on the spacing: the numerical dissipation
narrows the neck between the arcs, so the switch lies above ℓ* by an error that falls under
refinement. By the default upwind flux (``solver.options.hji.flux``) it is about 0.3 spacings and
falls as h (+0.0157, +0.0079, +0.0036 at 41, 81 and 161 nodes on [−1, 1]², T = 8); by local
Lax–Friedrichs, whose dissipation is the fastest control sample's, about as h^0.6 (+0.0407, +0.0282,
+0.0175), for about half the CPU per solve.

Run: ``python -m benchmarks.chauffeur_threshold [--box 1.0] [--nodes 41 81 161] [--horizon 8]
[--within 0.2 0.4] [--flux lax_friedrichs]`` (minutes; the 161-node grid about 20 minutes of CPU;
not part of the test suite).
"""

from __future__ import annotations

import argparse
import math
import time

from gamespec.compiling import CompiledModel
from gamespec.loader import load
from gamespec.solving import compile_spec

FILE = "problems/ch7/homicidal_chauffeur_reduced.yaml"


def isaacs_threshold(gamma: float) -> float:
    """Isaacs' threshold on ℓ/R: the barrier closes below it."""
    return math.sqrt(1 - gamma**2) + gamma * math.asin(gamma) - 1


def chauffeur_model(box: float, nodes: int, horizon: float, flux: str | None = None) -> CompiledModel:
    """The reduced chauffeur on ``[−box, box]²`` with ``nodes`` per axis up to ``horizon``, by the
    numerical Hamiltonian ``flux`` (``solver.options.hji.flux``; None: the default)."""
    sets = [f"solver.options.hji.nodes={nodes}", f"problem.time.final={horizon}"]
    sets += [] if flux is None else [f"solver.options.hji.flux={flux}"]
    sets += [f"solver.options.hji.lower=[{-box},{-box}]", f"solver.options.hji.upper=[{box},{box}]"]
    return compile_spec(load(FILE, sets))


def switch_bracket(model: CompiledModel, low: float, high: float, width: float) -> tuple[float, float]:
    """The ℓ at which ``metrics.capture_region.converged`` switches from True (``low``) to False
    (``high``), bisected to ``width``; a ValueError when the ends do not straddle it."""

    def closed(ell: float) -> bool:
        return bool(model.solve({"l": ell}).metrics["capture_region"]["converged"])

    if not closed(low) or closed(high):
        raise ValueError(f"the switch is not between l = {low} and {high}")
    while high - low > width:
        middle = (low + high) / 2
        low, high = (middle, high) if closed(middle) else (low, middle)
    return low, high


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--box", type=float, nargs="+", default=[1.0], help="half-widths of the box")
    parser.add_argument("--nodes", type=int, nargs="+", default=[41, 81, 161], help="odd nodes per axis")
    parser.add_argument("--horizon", type=float, nargs="+", default=[8.0], help="horizons T")
    parser.add_argument("--width", type=float, default=0.0025, help="the bracket's width in ℓ")
    parser.add_argument("--within", type=float, nargs=2, default=[0.2, 0.4], help="the ℓ to bisect")
    parser.add_argument("--flux", choices=["upwind", "lax_friedrichs"], help="solver.options.hji.flux")
    args = parser.parse_args()
    spec = load(FILE)
    gamma = float(spec.problem.parameters["gamma"])
    star = isaacs_threshold(gamma) * float(spec.problem.parameters["R"])
    print(f"Isaacs' threshold ℓ* = {star:.4f} (γ = {gamma})\n")
    print("| box | nodes | spacing | T | switch bracket | midpoint − ℓ* | CPU s |")
    print("|---|---|---|---|---|---|---|")
    for box in args.box:
        for horizon in args.horizon:
            for nodes in args.nodes:
                start = time.process_time()
                model = chauffeur_model(box, nodes, horizon, args.flux)
                low, high = switch_bracket(model, *args.within, args.width)
                print(
                    f"| ±{box:g} | {nodes} | {2 * box / (nodes - 1):.4f} | {horizon:g} | "
                    f"[{low:.4f}, {high:.4f}] | {(low + high) / 2 - star:+.4f} | "
                    f"{time.process_time() - start:.0f} |",
                    flush=True,
                )


if __name__ == "__main__":
    main()
