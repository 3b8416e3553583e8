"""The Monte Carlo engine: seeded draws with the right moments, Latin hypercube stratification,
intervals with their nominal coverage, and batched runs that do not depend on batching or mapper."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from scipy.special import ndtr

from gamespec.montecarlo import (
    MultivariateNormal,
    Normal,
    Uniform,
    proportion,
    run,
    sample,
    summarize,
)

Z_BOUND = 5.0
"""Largest accepted z-score of a sample statistic (odds of a 5σ miss ~1e-6 per comparison)."""


def test_draws_are_seeded_and_methods_differ():
    dists = {"a": Normal(1.0, 2.0), "b": Uniform(-1.0, 3.0, shape=(2,))}
    first, again = sample(dists, 50, seed=3), sample(dists, 50, seed=3)
    assert all(np.array_equal(first[k], again[k]) for k in dists)
    assert not np.array_equal(first["a"], sample(dists, 50, seed=4)["a"])
    assert not np.array_equal(first["a"], sample(dists, 50, seed=3, method="latin_hypercube")["a"])
    assert first["a"].shape == (50,) and first["b"].shape == (50, 2)


@pytest.mark.parametrize("method", ["random", "latin_hypercube"])
def test_moments_within_sampling_error(method):
    n = 4000
    draws = sample({"x": Normal(-2.0, 0.5), "y": Uniform(1.0, 4.0)}, n, seed=11, method=method)
    assert abs(draws["x"].mean() + 2.0) / (0.5 / np.sqrt(n)) < Z_BOUND
    # var of a sample variance of a normal: 2σ⁴/(n−1)
    assert abs(draws["x"].var(ddof=1) - 0.25) / np.sqrt(2 * 0.5**4 / (n - 1)) < Z_BOUND
    assert abs(draws["y"].mean() - 2.5) / (3.0 / np.sqrt(12 * n)) < Z_BOUND
    assert draws["y"].min() >= 1.0 and draws["y"].max() < 4.0


def test_latin_hypercube_puts_one_draw_in_each_probability_bin():
    n = 64
    draws = sample({"x": Normal(0.0, 1.0, shape=(3,)), "y": Uniform(0.0, 1.0)}, n, 5, "latin_hypercube")
    bins_x = np.floor(ndtr(draws["x"]) * n).astype(int)
    for column in bins_x.T:
        assert sorted(column) == list(range(n))
    assert sorted(np.floor(draws["y"] * n).astype(int)) == list(range(n))


def test_multivariate_normal_covariance_and_a_deterministic_component():
    cov = np.array([[2.0, 0.6, 0.0], [0.6, 1.0, 0.0], [0.0, 0.0, 0.0]])
    mean = np.array([1.0, -1.0, 7.0])
    n = 5000
    x = sample({"x": MultivariateNormal(mean, cov)}, n, seed=2)["x"]
    assert np.all(x[:, 2] == 7.0)
    sample_cov = np.cov(x[:, :2].T)
    var = np.diag(cov)[:2]
    se = np.sqrt((np.outer(var, var) + cov[:2, :2] ** 2) / n)
    assert np.max(np.abs(sample_cov - cov[:2, :2]) / se) < Z_BOUND
    with pytest.raises(ValueError, match="semidefinite"):
        MultivariateNormal(np.zeros(2), np.array([[1.0, 0.0], [0.0, -1.0]]))


def test_bad_distribution_parameters_are_refused():
    with pytest.raises(ValueError):
        Normal(0.0, -1.0)
    with pytest.raises(ValueError):
        Uniform(2.0, 1.0)
    with pytest.raises(ValueError, match="method"):
        sample({"x": Normal(0.0, 1.0)}, 3, 0, method="sobol")


def test_mean_interval_has_nominal_coverage():
    """Across 2000 independent experiments of 15 normal draws, the 90 % t-interval covers the true
    mean in a fraction whose own Wilson interval contains 0.90."""
    experiments = sample({"x": Normal(3.0, 2.0, shape=(15,))}, 2000, seed=8)["x"]
    summaries = summarize({str(i): row for i, row in enumerate(experiments)}, confidence=0.9)
    covered = np.array([s.ci_low <= 3.0 <= s.ci_high for s in summaries.values()])
    check = proportion(covered, confidence=0.999)
    assert check.low <= 0.9 <= check.high


def test_proportion_wilson_interval_inverts_the_score_test():
    """Wilson's endpoints are the p where the score statistic |p̂ − p| / √(p(1−p)/n) equals z."""
    events = np.arange(50) < 17
    p = proportion(events, confidence=0.9)
    z = 1.6448536269514722
    assert (p.successes, p.n, p.estimate) == (17, 50, 17 / 50)
    for end in (p.low, p.high):
        assert (p.estimate - end) ** 2 == pytest.approx(z * z * end * (1 - end) / 50)
    none = proportion(np.zeros(20, dtype=bool), confidence=0.9)
    assert none.low == 0.0
    assert none.high == pytest.approx(z * z / (20 + z * z))


def test_summary_counts_failed_samples():
    s = summarize({"y": np.array([1.0, np.nan, 3.0, np.inf])})["y"]
    assert (s.n, s.failures, s.mean, s.min, s.max) == (2, 2, 2.0, 1.0, 3.0)


def _square_and_sum(batch):
    return {"sq": batch["x"] ** 2, "total": batch["x"] + batch["v"].sum(axis=1)}


def test_batched_runs_do_not_depend_on_batch_size_or_mapper():
    draws = sample({"x": Normal(0.0, 1.0), "v": Uniform(0.0, 1.0, shape=(3,))}, 37, seed=1)
    whole = _square_and_sum(draws)
    serial = run(_square_and_sum, draws, batch_size=5)
    with ThreadPoolExecutor(2) as pool:
        threaded = run(_square_and_sum, draws, batch_size=4, mapper=pool.map)
    for k in whole:
        assert np.array_equal(serial[k], whole[k])
        assert np.array_equal(threaded[k], whole[k])


def test_a_batch_with_wrong_rows_is_refused():
    draws = sample({"x": Normal(0.0, 1.0)}, 6, seed=1)
    with pytest.raises(ValueError, match="one row per draw"):
        run(lambda b: {"y": b["x"][:1]}, draws, batch_size=3)
