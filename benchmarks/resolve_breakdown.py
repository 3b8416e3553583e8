"""Where the time of a re-solve goes: a 20-point ``evader.speed`` sweep of the two-on-one
constant-bearing engagement, compiled once, with timers around the parts of each re-solve (CPU
time of the process, which other work on a shared machine does not inflate as it does wall time).

Run: ``python -m benchmarks.resolve_breakdown [--points 20] [--repeat 3]`` (seconds; not part of
the test suite). The timers wrap, by name and only where they exist (so the script also measures
an older checkout put first on ``PYTHONPATH``): the compiled model's ``solve`` (the share the
benchmark ``test_bench_resolve_engagement.py`` asserts), the engagement transform's ``apply`` and
``parameter_map``, the re-simulation inside ``invert`` (``ocp_report``'s ``simulate_to_capture``),
the rest of ``invert``, ``verify`` and the re-validation of the source spec (``with_values``).
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import gamespec
from gamespec import solving
from gamespec.pursuit import ocp_report
from gamespec.transforms.engagement import EngagementToOcp

FILE = Path(__file__).resolve().parents[1] / "problems" / "ch2" / "constant_bearing_two_on_one.yaml"


class Timers:
    """Accumulated CPU seconds (this process, all its threads) per label, of wrapped callables."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = defaultdict(float)

    def wrap(self, label: str, function: Callable[..., Any]) -> Callable[..., Any]:
        def timed(*args: Any, **kwargs: Any) -> Any:
            start = time.process_time()
            try:
                return function(*args, **kwargs)
            finally:
                self.seconds[label] += time.process_time() - start

        return timed


def instrument(timers: Timers) -> None:
    """Wrap the parts of a re-solve but the compiled model's ``solve`` (see module doc)."""
    ocp_report.simulate_to_capture = timers.wrap("invert: re-simulation", ocp_report.simulate_to_capture)
    for method, label in (
        ("apply", "transform apply"),
        ("parameter_map", "parameter_map"),
        ("invert", "invert (all)"),
        ("verify", "verify"),
    ):
        if hasattr(EngagementToOcp, method):
            setattr(EngagementToOcp, method, timers.wrap(label, getattr(EngagementToOcp, method)))
    solving.with_values = timers.wrap("with_values", solving.with_values)


def sweep(timers: Timers, points: int, analyses: bool) -> tuple[float, dict[str, float], list[float]]:
    """Per-point CPU time, per-point CPU seconds by label and the capture times of one sweep."""
    keyword = {} if analyses else {"analyses": "none"}
    solver = gamespec.compile_spec(gamespec.load(FILE), **keyword)
    solver.solve(parameters={"evader.speed": 0.45})
    timers.seconds.clear()
    solver.compiled.solve = timers.wrap("CompiledModel.solve", solver.compiled.solve)
    speeds = [float(v) for v in np.linspace(0.3, 0.6, points)]
    start = time.process_time()
    answers = [solver.solve(parameters={"evader.speed": v}).t_final for v in speeds]
    total = (time.process_time() - start) / points
    return total, {k: v / points for k, v in timers.seconds.items()}, answers


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=20)
    parser.add_argument("--repeat", type=int, default=3, help="sweeps; the fastest is reported")
    parser.add_argument("--analyses-none", action="store_true", help="compile with analyses='none'")
    args = parser.parse_args()
    print(f"gamespec from {Path(gamespec.__file__).parent}")
    timers = Timers()
    instrument(timers)
    best = None
    for _ in range(args.repeat):
        run = sweep(timers, args.points, analyses=not args.analyses_none)
        if best is None or run[0] < best[0]:
            best = run
    total, parts, answers = best
    print(f"{args.points} points, per point {1e3 * total:.2f} ms of CPU")
    for label, seconds in sorted(parts.items(), key=lambda kv: -kv[1]):
        print(f"  {label:28s} {1e3 * seconds:8.2f} ms  {100 * seconds / total:5.1f} %")
    inside = parts["CompiledModel.solve"]
    resim = parts.get("invert: re-simulation", 0.0)
    print(f"share inside CompiledModel.solve: {100 * inside / total:.1f} %")
    print(f"share with the re-simulation in invert subtracted: {100 * inside / (total - resim):.1f} %")
    print("capture times:", " ".join(f"{t:.10g}" for t in answers))


if __name__ == "__main__":
    main()
