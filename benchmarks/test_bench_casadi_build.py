"""The CasADi build at N = 1000 Radau intervals (issue 16) on the cart-pole swing-up (Kelly 2017) and
both Zermelo files: the default ``assembled`` graph against the flat ``sx`` graph (the earlier
default), measured in the same run in CPU time (``time.process_time``, steadier than wall time on a
shared machine).

Goals, as ratios: the build takes no longer than the first IPOPT solve (``build / solve <= 1``), and
a re-solve of the compiled model with a new parameter is as fast as on the flat graph (``re-solve
assembled / re-solve sx`` about 1); both graphs reach the same optimum (objective to 1e-8).

Run: ``python -m pytest benchmarks/test_bench_casadi_build.py --benchmark-enable -m slow -s``; each
case prints build, solve and re-solve seconds per graph and the ratios.
"""

from __future__ import annotations

import gc
import time

import pytest

import gamespec
from gamespec.solving import get_backend
from tests.conftest import PROBLEMS

FILES = {
    "cart_pole": (PROBLEMS / "ocp" / "cart_pole_swing_up.yaml", {"d": 0.9}),
    "zermelo_min_time": (PROBLEMS / "ch6" / "zermelo_min_time.yaml", {"rho": 9.0}),
    "zermelo_max_range": (PROBLEMS / "ch6" / "zermelo_max_range.yaml", {"rho": 9.0}),
}
GRAPHS = ("assembled", "sx")


def _build_solve_resolve(path, graph: str, parameters: dict[str, float]) -> dict[str, float]:
    """CPU seconds of the compile, the first solve and a re-solve with new parameter values, and the
    two objectives."""
    spec = gamespec.load(path, ["method.intervals=1000", f"solver.options.casadi.graph={graph}"])
    gc.collect()
    tic = time.process_time()
    model = get_backend("casadi").compile(spec)
    built = time.process_time()
    first = model.solve()
    solved = time.process_time()
    again = model.solve(parameters=parameters)
    resolved = time.process_time()
    assert first.ok and again.ok
    times = {"build": built - tic, "solve": solved - built, "resolve": resolved - solved}
    del model
    gc.collect()
    return times | {"objective": first.objective, "objective_again": again.objective}


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(FILES))
def test_build_within_the_solve_and_resolves_as_fast(benchmark, case: str) -> None:
    path, parameters = FILES[case]
    benchmark.group = f"{case}, N = 1000"
    runs: dict[str, dict[str, float]] = {}

    def measure() -> None:
        for graph in GRAPHS:
            runs[graph] = _build_solve_resolve(path, graph, parameters)

    benchmark.pedantic(measure, rounds=1)
    new, old = runs["assembled"], runs["sx"]
    ratios = {
        "build/solve assembled": new["build"] / new["solve"],
        "build/solve sx": old["build"] / old["solve"],
        "resolve assembled/sx": new["resolve"] / old["resolve"],
    }
    benchmark.extra_info.update({f"{g} {k}": v for g, run in runs.items() for k, v in run.items()} | ratios)
    for graph, run in runs.items():
        print(
            f"\n{case} {graph}: build {run['build']:.3f} s, solve {run['solve']:.3f} s, "
            f"re-solve {run['resolve']:.3f} s"
        )
    print(", ".join(f"{k} {v:.2f}" for k, v in ratios.items()))
    assert new["objective"] == pytest.approx(old["objective"], rel=1e-8)
    assert new["objective_again"] == pytest.approx(old["objective_again"], rel=1e-8)
    assert ratios["build/solve assembled"] <= 1.0
