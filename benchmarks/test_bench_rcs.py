"""One RCS solve per number of obstacles (§6.4.4: the thesis reports "a few milliseconds"). Each N
is timed twice in its own group: the RCS problem (α = 0.33, the sensitivity cost of eq. 6.36 in the
objective) and its baseline, the same problem with α = 0 (avoidance constraints only), so the cost
of the regularizer reads off as a ratio measured in the same run. Cold solves (warm start off) of a
model built once, from the study's first guess; the Monte Carlo is off.

Run: ``python -m pytest benchmarks/test_bench_rcs.py --benchmark-enable``.
"""

from __future__ import annotations

import pytest

from gamespec.loader import spec_from_dict
from gamespec.rcs.study_points import point_problem
from gamespec.rcs.study_spec import RcsStudySpec
from gamespec.solving import compile_spec

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
