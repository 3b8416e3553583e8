"""The Pyomo backend at large N (issue 16, item 7): the NL file written once per compiled model
against Pyomo's ``SolverFactory`` writing the whole file on every solve (the backend before), on
Zermelo's minimum-time file and the cart-pole swing-up at N = 100, 300 and 1000 Radau intervals.

Per size, on one compiled model: the NL text alone (a fresh write of the model by Pyomo's writer
against :meth:`NLFile.text`), then cold re-solves (from the file's guess, so both paths solve the
same NLP from the same start) through either path, interleaved, the smallest time of each kept.
Times are CPU seconds of this process (the NL text, the SOL file, loading, the Result) and the
solver's own wall time from its log (``wall_time`` of ripopt, ``Total seconds in IPOPT``) and its
process's CPU time (steadier on a shared machine), also per iteration (the cart-pole's iteration
count is not monotone in N); ``test_growth_exponents`` fits
``t ~ N^k`` over the sizes, and the last test times ripopt alone on a plain chain NLP. Both paths
must reach the same optimum (1e-8 relative) with the same iteration count.

Run: ``python -m pytest benchmarks/test_bench_pyomo.py --benchmark-enable -m slow -s``.
"""

from __future__ import annotations

import io
import resource
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest
from gamespec_pyomo.nlfile import WRITER_CONFIG, NLFile
from gamespec_pyomo.solvers import (
    PRINT_LEVEL,
    Run,
    find_executable,
    pyomo_solver,
    run_solver,
    solver_seconds_in,
)
from pyomo.repn.plugins.nl_writer import NLWriter

import gamespec
from gamespec.solving import get_backend
from tests.conftest import PROBLEMS

FILES = {
    "zermelo_min_time": PROBLEMS / "ch6" / "zermelo_min_time.yaml",
    "cart_pole": PROBLEMS / "ocp" / "cart_pole_swing_up.yaml",
}
SIZES = (100, 300, 1000)
PAIRS = 2
_ROWS: dict[tuple[str, int], dict[str, float]] = {}


def _whole_file(compiled) -> Run:
    """The backend before: Pyomo's SolverFactory writes the whole NL file, runs the executable and
    loads the SOL file through its symbol map."""
    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / "solver.log"
        results = pyomo_solver(compiled.executable).solve(
            compiled.model, options=compiled._solver_options(), logfile=str(log), load_solutions=False
        )
        if len(results.solution) > 0:
            compiled.model.solutions.load_from(results)
        return Run(results, log.read_text(), results.solver.time)


def _fresh_write(model) -> None:
    NLWriter().write(model, io.StringIO(), None, None, **WRITER_CONFIG)


def _cpu(call) -> tuple[float, object]:
    tic = time.process_time()
    out = call()
    return time.process_time() - tic, out


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _timed_solve(compiled) -> dict[str, float]:
    before = _children_cpu()
    cpu, result = _cpu(compiled.solve)
    assert result.ok, result.message
    return {
        "cpu": cpu,
        "solver": result.solver_stats["solver_time_s"],
        "solver_cpu": _children_cpu() - before,
        "objective": result.objective,
        "iterations": result.iterations,
    }


@pytest.mark.slow
@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("case", sorted(FILES))
def test_resolve_new_against_old(benchmark, monkeypatch, case: str, n: int) -> None:
    benchmark.group = f"pyomo {case}, N = {n}"
    spec = gamespec.load(FILES[case], [f"method.intervals={n}", "solver.options.pyomo.warm_start=false"])
    compiled = get_backend("pyomo").compile(spec)
    compiled.solve()
    write = {"old": min(_cpu(lambda: _fresh_write(compiled.model))[0] for _ in range(PAIRS))}
    write["new"] = min(_cpu(compiled.nl.text)[0] for _ in range(PAIRS))
    new_execute = compiled._execute
    runs: dict[str, list[dict[str, float]]] = {"old": [], "new": []}
    for _ in range(PAIRS):
        for path in ("old", "new"):
            execute = new_execute if path == "new" else lambda: _whole_file(compiled)
            monkeypatch.setattr(compiled, "_execute", execute)
            runs[path].append(_timed_solve(compiled))
    old, new = (min(runs[p], key=lambda r: r["cpu"]) for p in ("old", "new"))
    assert new["objective"] == pytest.approx(old["objective"], rel=1e-8)
    assert new["iterations"] == old["iterations"]
    row = {
        "write_old_s": write["old"],
        "write_new_s": write["new"],
        "write_ratio": write["new"] / write["old"],
        "ours_old_s": old["cpu"],
        "ours_new_s": new["cpu"],
        "ours_ratio": new["cpu"] / old["cpu"],
        "solver_s": min(r["solver"] for r in runs["old"] + runs["new"]),
        "solver_cpu_s": min(r["solver_cpu"] for r in runs["old"] + runs["new"]),
        "iterations": new["iterations"],
    }
    row["solver_cpu_per_iteration_s"] = row["solver_cpu_s"] / row["iterations"]
    _ROWS[case, n] = row
    benchmark.extra_info.update(row)
    benchmark.pedantic(compiled.nl.text, rounds=1)
    print(f"\n{case} N={n}: " + ", ".join(f"{k}={v:.3g}" for k, v in row.items()))


def _exponent(case: str, key: str) -> float:
    """The least-squares slope of log(time) against log(N)."""
    times = [_ROWS[case, n][key] for n in SIZES]
    return float(np.polyfit(np.log(SIZES), np.log(times), 1)[0])


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(FILES))
def test_growth_exponents(benchmark, case: str) -> None:
    if any((case, n) not in _ROWS for n in SIZES):
        pytest.skip("needs every size of this case in the same run")
    benchmark.group = f"pyomo {case}, growth exponents"
    keys = ("write_old_s", "write_new_s", "ours_old_s", "ours_new_s", "solver_s", "solver_cpu_s")
    keys += ("solver_cpu_per_iteration_s",)
    exponents = {key: _exponent(case, key) for key in keys}
    benchmark.extra_info.update(exponents)
    benchmark.pedantic(lambda: None, rounds=1)
    print(f"\n{case}: N-growth exponents " + ", ".join(f"{k}={v:.2f}" for k, v in exponents.items()))


def _chain(n: int, one_sum: bool):
    """min sum (x_i - 1/2)^2 subject to x_{i+1} = x_i + sin(x_i)/1000: the objective as one expression
    over all n variables, or as n epigraph rows y_i = (x_i - 1/2)^2 under a linear objective."""
    import pyomo.environ as pyo

    m = pyo.ConcreteModel()
    m.x = pyo.Var(range(n), initialize=1.0)
    step = lambda m, i: m.x[i + 1] - m.x[i] - 1e-3 * pyo.sin(m.x[i]) == 0  # noqa: E731
    m.chain = pyo.Constraint(range(n - 1), rule=step)
    if one_sum:
        m.objective = pyo.Objective(expr=sum((m.x[i] - 0.5) ** 2 for i in range(n)))
    else:
        m.y = pyo.Var(range(n), initialize=0.0)
        m.epigraph = pyo.Constraint(range(n), rule=lambda m, i: m.y[i] == (m.x[i] - 0.5) ** 2)
        m.objective = pyo.Objective(expr=sum(m.y[i] for i in range(n)))
    return m


@pytest.mark.slow
@pytest.mark.parametrize("one_sum", [False, True], ids=["epigraph_rows", "one_sum"])
def test_ripopt_growth_on_a_plain_chain(benchmark, one_sum: bool) -> None:
    """ripopt's own wall time on a problem with no collocation in it, at n = 1000 and 3000: the
    growth exponent of the solver alone (and of its Hessian of one expression in n variables)."""
    exe = find_executable("ripopt")
    benchmark.group = "ripopt alone, growth exponent"
    times: dict[str, list[float]] = {"solver_s": [], "solver_cpu_s": []}
    for n in (1000, 3000):
        before = _children_cpu()
        run = run_solver(exe, NLFile(_chain(n, one_sum)).text(), {"print_level": PRINT_LEVEL["ripopt"]})
        times["solver_cpu_s"].append(_children_cpu() - before)
        times["solver_s"].append(solver_seconds_in(run.log))
        assert str(run.results.solver.termination_condition) == "optimal"
    exponents = {key: float(np.log(t[1] / t[0]) / np.log(3.0)) for key, t in times.items()}
    benchmark.extra_info.update(times | {f"exponent_{key}": k for key, k in exponents.items()})
    benchmark.pedantic(lambda: None, rounds=1)
    name = "one sum" if one_sum else "epigraph rows"
    print(f"\nripopt alone ({name}) at n = 1000, 3000: {times}, exponents {exponents}")
