"""The fast active-pursuer check against AAPC (Algorithm 1), and one MPME simulation step.

Goals (issue 5): the fast check ≥ 100× AAPC at n = 1 000 and under 100 ms at n = 10 000; a
100 × 50 MPME simulation step (allocation included) under 50 ms. Layouts: pursuers uniform in a
square around the evader, a jittered ring around it (few pursuers can be dropped early), and
(issue 16) pursuers of one speed exactly on a circle around it, whose dual points are coplanar, with
the same circle jittered by 1e-6 (general position) as its baseline: 1 000 co-circular pursuers
under 50 ms. AAPC is ``O(n**2)`` per pursuer, ``O(n**3)`` in all; it is skipped at n = 10 000 (and
from n = 1 000 on the circles, where no pursuer is dropped early).

Run: ``python -m pytest benchmarks/test_bench_geometric.py --benchmark-enable``; compare the means
in each group.
"""

from __future__ import annotations

import statistics
import time

import numpy as np
import pytest
import yaml
from gamespec_geometric import active_pursuers, allocation, simulation
from gamespec_geometric.simulation import simulate

import gamespec
from gamespec.loader import spec_from_dict
from tests.conftest import PROBLEMS

SIZES = [10, 100, 1_000, 10_000]


def _layout(kind: str, n: int) -> np.ndarray:
    rng = np.random.default_rng(n)
    if kind == "uniform":
        return rng.uniform(-50, 50, (n, 2))
    angle = rng.uniform(-np.pi, np.pi, n)
    radius = {"ring": 20 + rng.uniform(-1, 1, n), "circle": np.full(n, 20.0)}.get(kind)
    if radius is None:
        radius = 20 + rng.uniform(-1e-6, 1e-6, n)
    return radius[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])


@pytest.mark.parametrize("layout", ["uniform", "ring", "circle", "jittered circle"])
@pytest.mark.parametrize("n", SIZES)
@pytest.mark.parametrize("method", ["fast", "reference"])
def test_active_check(benchmark, method: str, n: int, layout: str) -> None:
    benchmark.group = f"active check, {layout}, n={n}"
    if method == "reference" and (n > 1_000 or (n == 1_000 and "circle" in layout)):
        pytest.skip("AAPC is O(n^3): it does not finish at this size")
    pursuers = _layout(layout, n)
    evader = np.zeros(2) if "circle" in layout else np.array([0.5, -0.3])
    if method == "reference" and n == 1_000:
        status = benchmark.pedantic(
            active_pursuers, (pursuers, evader, 1.0, 0.6), {"method": method}, rounds=1, iterations=1
        )
    else:
        status = benchmark(active_pursuers, pursuers, evader, 1.0, 0.6, method=method)
    assert status.any()


@pytest.mark.parametrize("strategy", ["cb", "pp"])
def test_mpme_step_100_on_50(benchmark, strategy: str) -> None:
    benchmark.group = "MPME simulation step, 100 pursuers x 50 evaders"
    rng = np.random.default_rng(5)
    spec = spec_from_dict(
        {
            "kind": "pursuit_scenario",
            "pursuers": {"positions": rng.uniform(-50, 50, (100, 2)).tolist(), "strategy": strategy},
            "evaders": {
                "positions": rng.uniform(-50, 50, (50, 2)).tolist(),
                "strategy": {"type": "pure_evasion"},
            },
            "time_step": 0.01,
            "horizon": 0.01,
        }
    )
    run = benchmark(simulate, spec)
    assert len(run.time) == 2


def _ten_on_five_copy(pursuers: int, evaders: int, steps: int) -> dict:
    """``problems/ch3/mpme_ten_on_five.yaml`` (AVAA, CB, blind evaders) with random teams of a given size."""
    data = yaml.safe_load((PROBLEMS / "ch3" / "mpme_ten_on_five.yaml").read_text())
    if pursuers != len(data["pursuers"]["positions"]):
        rng = np.random.default_rng(5)
        data["pursuers"]["positions"] = rng.uniform(-50, 50, (pursuers, 2)).tolist()
        data["evaders"]["positions"] = rng.uniform(-50, 50, (evaders, 2)).tolist()
    data["horizon"] = steps * data["time_step"]
    return data


def _one_evader_at_a_time(pursuers, evaders, u, v, *, algorithm, strategy, method, samples):
    """The allocation with the active sets checked evader by evader (the path before issue 16)."""
    cost = allocation.tie_break_cost(pursuers, evaders, u, v, algorithm)
    check = allocation._one_by_one(pursuers, evaders, u, v, strategy, method, samples)
    return allocation._iterate(cost, check, len(pursuers) + 1)


@pytest.mark.parametrize("case", ["10 x 5", "100 x 50", "100 x 50, one evader at a time"])
def test_mpme_copy_steps(benchmark, monkeypatch, case: str) -> None:
    """Issue 16: the 100 × 50 copy of the ten-on-five file at ≤ 20 ms per step (20 steps here), with
    the file itself and the evader-by-evader allocation as baselines; allocations agree."""
    benchmark.group = "MPME ten-on-five copies, 20 steps"
    size = (10, 5) if case == "10 x 5" else (100, 50)
    spec = spec_from_dict(_ten_on_five_copy(*size, steps=20))
    expected = simulate(spec).allocation
    if "one evader" in case:
        monkeypatch.setattr(simulation, "allocate", _one_evader_at_a_time)
    run = benchmark.pedantic(simulate, (spec,), rounds=3, warmup_rounds=1)
    np.testing.assert_array_equal(run.allocation, expected)


def _cpu_per_step(spec) -> float:
    """CPU seconds per simulation step of a whole ``gamespec.solve`` of ``spec`` (the chain the
    command line runs: load excluded, the simulation to its end included)."""
    start = time.process_time()
    result = gamespec.solve(spec)
    assert result.status == "simulated"
    return (time.process_time() - start) / result.iterations


def test_mpme_whole_run_per_step(benchmark) -> None:
    """Issue 29: the whole run of the 100 × 50 copy of the ten-on-five file (every evader captured)
    at ≤ 6× the per-step CPU of the 10 × 5 file itself, both run to their end, interleaved (median
    of 3)."""
    benchmark.group = "MPME whole runs, CPU per step"
    small = spec_from_dict(_ten_on_five_copy(10, 5, steps=6000))
    large = spec_from_dict(_ten_on_five_copy(100, 50, steps=6000))

    def interleaved() -> tuple[float, float]:
        pairs = [(_cpu_per_step(small), _cpu_per_step(large)) for _ in range(3)]
        return statistics.median(p[0] for p in pairs), statistics.median(p[1] for p in pairs)

    per_small, per_large = benchmark.pedantic(interleaved, rounds=1, iterations=1)
    ratio = per_large / per_small
    benchmark.extra_info |= {"ms_per_step_10x5": 1e3 * per_small, "ms_per_step_100x50": 1e3 * per_large}
    benchmark.extra_info["ratio"] = ratio
    print(f"\n10 x 5: {1e3 * per_small:.2f} ms/step, 100 x 50: {1e3 * per_large:.2f} ms/step, {ratio:.1f}x")
    assert ratio <= 6.0
