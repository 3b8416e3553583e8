"""One RCS solve per number of obstacles (§6.4.4: the thesis reports "a few milliseconds"). Each N
is timed twice in its own group: the RCS problem (α = 0.33, the sensitivity cost of eq. 6.36 in the
objective) and its baseline, the same problem with α = 0 (avoidance constraints only), so the cost
of the regularizer reads off as a ratio measured in the same run. Cold solves (warm start off) of a
model built once, from the study's first guess; the Monte Carlo is off.

Issue 29, item 3 (CPU time, ratios within the same run; the absolute CPU printed with ``-s``):

- :func:`test_warm_resolve`: a re-solve of the compiled ``rcs_single_obstacle`` model over α and σ
  (:data:`POINTS`, every one new to the analyses' cache, so each runs its Monte Carlo) costs at
  most :data:`WARM_GOAL` of a cold compile and solve of the same file;
- :func:`test_study_point`: a point of the §6.4.4 study on the compiled model of its N costs at most
  :data:`POINT_GOAL` of the previous route, a compile and solve per guess (the same answers);
- :func:`test_full_study` (slow): the 16 points serially, one compile per N, the total printed.

Run: ``python -m pytest benchmarks/test_bench_rcs.py --benchmark-enable -s`` (``-m slow`` for the
whole study).
"""

from __future__ import annotations

import time

import pytest

from gamespec.analyses import for_study
from gamespec.loader import load, spec_from_dict, with_values
from gamespec.rcs import multi_obstacle_study
from gamespec.rcs.study_points import point_problem, study_points
from gamespec.rcs.study_spec import RcsStudySpec
from gamespec.solving import compile_spec, solve
from tests.conftest import PROBLEMS

SINGLE = PROBLEMS / "ch6" / "rcs_single_obstacle.yaml"
STUDY = PROBLEMS / "ch6" / "rcs_multi_obstacle_study.yaml"
SIGMA = "problem.uncertain.rho.normal.std"
POINTS = [{"Q": q, SIGMA: s} for q, s in [(0.8, 0.12), (0.9, 0.15), (1.1, 0.2), (1.2, 0.25), (1.0, 0.3)]]
"""(α, σ) near the file's (Q = 1, σ = 0.1): one homotopy class, each re-solve warm from the last."""
WARM_GOAL = 0.2
POINT_GOAL = 0.5

COUNTS = (2, 3, 5, 10)


@pytest.mark.parametrize("alpha", [0.0, 0.33], ids=["baseline", "rcs"])
@pytest.mark.parametrize("n", COUNTS)
def test_rcs_solve(benchmark, n: int, alpha: float) -> None:
    study = RcsStudySpec(name="bench")
    data = point_problem(study, n, 0.33, study.guesses[0])
    data["transforms"][1]["rcs"]["monte_carlo"] = {"samples": 0}
    solver = compile_spec(spec_from_dict(data), "casadi", {"warm_start": False})
    benchmark.group = f"rcs solve, N = {n}"
    result = benchmark.pedantic(
        solver.solve, kwargs={"parameters": {"problem.parameters.alpha": alpha}}, rounds=3, warmup_rounds=1
    )
    assert result.ok


def _cpu(function, *args, **kwargs):
    start = time.process_time()
    out = function(*args, **kwargs)
    return time.process_time() - start, out


def test_warm_resolve(benchmark) -> None:
    benchmark.group = "rcs_single_obstacle: warm re-solve over alpha and sigma"
    cold, first = _cpu(lambda: compile_spec(with_values(load(SINGLE), POINTS[0])).solve())
    solver = compile_spec(SINGLE)
    solver.solve()
    seconds = []

    def resolve_all() -> list[float]:
        objectives = []
        for point in POINTS:
            spent, result = _cpu(solver.solve, parameters=point)
            assert result.ok and "collision_probability" in result.metrics["monte_carlo"]
            seconds.append(spent)
            objectives.append(result.objective)
        return objectives

    objectives = benchmark.pedantic(resolve_all, rounds=1, iterations=1)
    assert objectives[0] == pytest.approx(first.objective, rel=1e-8)
    warm = sum(seconds) / len(seconds)
    benchmark.extra_info |= {"cold_s": cold, "warm_s": warm, "ratio": warm / cold}
    print(
        f"\nrcs_single_obstacle: cold compile+solve {1e3 * cold:.0f} ms CPU, warm re-solve over "
        f"(alpha, sigma) {1e3 * warm:.1f} ms CPU per solve (Monte Carlo included), ratio {warm / cold:.3f}"
    )
    assert warm <= WARM_GOAL * cold


def _old_point(spec: RcsStudySpec, n: int, alpha: float) -> float:
    """The previous route of one point: a compile and solve per guess; the best objective."""
    best = None
    for amplitude in spec.guesses:
        data = point_problem(spec, n, alpha, amplitude)
        analyses = for_study(spec.analyses, multi_obstacle_study.TABLE_ANALYSES)
        result = solve(spec_from_dict(data), spec.ocp_backend, analyses=analyses)
        if result.ok and (best is None or result.objective < best):
            best = result.objective
    assert best is not None
    return best


@pytest.mark.parametrize("n", [2, 5])
def test_study_point(benchmark, n: int) -> None:
    benchmark.group = f"rcs study point N = {n}: compiled model per N vs compile per guess"
    spec = load(STUDY)
    points = [p for p in study_points(spec).values() if p.obstacles == n]
    multi_obstacle_study.compiled_point.cache_clear()
    multi_obstacle_study.evaluate(points[0])  # compiles the model of this N
    new = []

    def run() -> list[dict]:
        rows = []
        for point in points[1:]:
            spent, row = _cpu(multi_obstacle_study.evaluate, point)
            new.append(spent)
            rows.append(row)
        return rows

    rows = benchmark.pedantic(run, rounds=1, iterations=1)
    old, objective = _cpu(_old_point, spec, n, points[-1].alpha)
    assert rows[-1]["objective"] == pytest.approx(objective, rel=1e-8)
    per_point = sum(new) / len(new)
    benchmark.extra_info |= {"per_point_s": per_point, "old_point_s": old, "ratio": per_point / old}
    print(
        f"\nrcs study N = {n}: {per_point:.2f} s CPU per point on the compiled model, "
        f"{old:.2f} s by a compile per guess, ratio {per_point / old:.3f}"
    )
    assert per_point <= POINT_GOAL * old


@pytest.mark.slow
def test_full_study(benchmark) -> None:
    benchmark.group = "rcs study: 16 points serially"
    spec = load(STUDY)
    multi_obstacle_study.compiled_point.cache_clear()
    points = list(study_points(spec).values())

    def run() -> list[dict]:
        return [multi_obstacle_study.evaluate(p) for p in points]

    total, rows = _cpu(benchmark.pedantic, run, rounds=1, iterations=1)
    assert all(r["status"] != "error" for r in rows)
    benchmark.extra_info |= {"total_s": total}
    print(f"\nrcs study: {len(points)} points in {total:.1f} s CPU ({total / len(points):.2f} s per point)")
