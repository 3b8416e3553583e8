"""A re-solve costs the solve (issue 24, item 1): a 20-point ``evader.speed`` sweep of the two-on-one
constant-bearing engagement, compiled once, must spend at least :data:`GOAL` of its per-point time
inside the compiled model's ``solve`` (IPOPT and the checks compiled with the model), the rest being
the parameter maps, the inverse maps and the Result's bookkeeping.

The share is a ratio within the same run: the CPU time inside ``CompiledModel.solve`` (timed by
wrapping the compiled model's ``solve``) over the CPU time of the sweep's ``Solver.solve`` calls
(CPU, not wall time: on a shared machine other work stretches the wall time of both parts by
chance), written to the benchmark's ``extra_info`` and to the terminal. The sweep compiles with
``analyses="none"`` (issue 24, item 2: the re-simulation is the engagement's ``resimulation``
analysis, not part of ``invert``); the share is also reported with the re-simulation's time
subtracted, which must agree when the analysis is really off.

Run: ``python -m pytest benchmarks/test_bench_resolve_engagement.py --benchmark-enable -s``; the
per-part breakdown: ``python -m benchmarks.resolve_breakdown``.
"""

from __future__ import annotations

import time

import numpy as np

import gamespec
from gamespec.pursuit import ocp_report
from tests.conftest import PROBLEMS

FILE = PROBLEMS / "ch2" / "constant_bearing_two_on_one.yaml"
SPEEDS = [float(v) for v in np.linspace(0.3, 0.6, 20)]
GOAL = 0.80


def _timed(seconds: list[float], function):
    def timed(*args, **kwargs):
        start = time.process_time()
        try:
            return function(*args, **kwargs)
        finally:
            seconds.append(time.process_time() - start)

    return timed


def test_resolve_time_is_solve_time(benchmark, monkeypatch) -> None:
    benchmark.group = "re-solve: 20 evader speeds"
    solver = gamespec.compile_spec(gamespec.load(FILE), analyses="none")
    solver.solve(parameters={"evader.speed": 0.45})
    inside: list[float] = []
    resimulation: list[float] = []
    solver.compiled.solve = _timed(inside, solver.compiled.solve)
    monkeypatch.setattr(
        ocp_report, "simulate_to_capture", _timed(resimulation, ocp_report.simulate_to_capture)
    )

    def sweep() -> list[float]:
        inside.clear()
        resimulation.clear()
        return [solver.solve(parameters={"evader.speed": v}).t_final for v in SPEEDS]

    start = time.process_time()
    capture_times = benchmark.pedantic(sweep, rounds=1, iterations=1)
    total = time.process_time() - start
    assert len(inside) == len(SPEEDS)  # one solve a point: no multi-start inflates the share
    assert len(set(capture_times)) == len(SPEEDS)
    assert np.all(np.diff(capture_times) > 0)  # a faster evader is caught later
    share = sum(inside) / total
    without = sum(inside) / (total - sum(resimulation))
    benchmark.extra_info |= {
        "per_point_s": total / len(SPEEDS),
        "share": share,
        "share_without_resim": without,
    }
    print(
        f"\nper point {1e3 * total / len(SPEEDS):.2f} ms of CPU, inside CompiledModel.solve "
        f"{100 * share:.1f} %, {100 * without:.1f} % with the re-simulation in invert subtracted"
    )
    assert sum(resimulation) == 0.0, "the re-simulation ran with the analyses off"
    assert share >= GOAL
