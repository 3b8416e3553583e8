"""Eq. 5.39: the Gaussian mass of a disk against closed forms and Monte Carlo."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import ncx2, norm

from gamespec.flowfield.capture_probability import disk_probability


@pytest.mark.parametrize("sigma", [1e-3, 0.03, 0.09, 1.0])
@pytest.mark.parametrize("offset", [0.0, 0.05, 0.3])
def test_isotropic_is_the_noncentral_chi_square(sigma: float, offset: float) -> None:
    """``‖z‖²/σ² ~ χ'²(2, ‖μ‖²/σ²)`` for ``Σ = σ²I``."""
    mean = offset * np.array([0.6, 0.8])
    centred = 1 - np.exp(-(0.09**2) / (2 * sigma**2))
    expected = ncx2.cdf(0.09**2 / sigma**2, 2, offset**2 / sigma**2) if offset else centred
    assert disk_probability(mean, sigma**2 * np.eye(2), 0.09) == pytest.approx(expected, abs=1e-10)


def test_degenerate_covariances_are_limits() -> None:
    assert disk_probability([0.05, 0.0], np.zeros((2, 2)), 0.09) == 1.0
    assert disk_probability([0.1, 0.0], np.zeros((2, 2)), 0.09) == 0.0
    line = disk_probability([0.0, 0.03], np.diag([0.04**2, 0.0]), 0.09)
    chord = np.sqrt(0.09**2 - 0.03**2)
    assert line == pytest.approx(norm.cdf(chord / 0.04) - norm.cdf(-chord / 0.04), abs=1e-9)


def test_correlated_gaussian_against_monte_carlo() -> None:
    rng = np.random.default_rng(7)
    mean, cov = np.array([0.03, -0.02]), np.array([[0.003, 0.001], [0.001, 0.0005]])
    z = rng.multivariate_normal(mean, cov, size=400_000)
    hit = np.mean(np.linalg.norm(z, axis=1) <= 0.09)
    p = disk_probability(mean, cov, 0.09)
    assert abs(hit - p) < 4 * np.sqrt(p * (1 - p) / z.shape[0])


def test_a_smaller_centred_covariance_captures_more() -> None:
    """Anderson's theorem: for a centred Gaussian and a symmetric convex set (the disk), ``P`` does
    not increase when ``Σ`` grows in the Loewner order — why the pursuer's feedback, which keeps the
    mean (feedforward nominal) and shrinks ``Σʳ``, raises eq. 5.39 where the mean is near zero."""
    rng = np.random.default_rng(3)
    for _ in range(20):
        X, Y = rng.normal(size=(2, 2, 2)) * 0.05
        small = X @ X.T
        large = small + Y @ Y.T
        assert (
            disk_probability(np.zeros(2), small, 0.09) >= disk_probability(np.zeros(2), large, 0.09) - 1e-10
        )
