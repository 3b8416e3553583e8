"""The capture probability of eq. 5.39: the Gaussian mass of the disk ``‖x‖ ≤ ε``.

For ``z ~ N(μ, Σ)`` in the plane, rotate to the eigenvectors of Σ (standard deviations
``s₁ ≥ s₂``, centre ``m``) and integrate the inner axis in closed form:
``P = ∫_{−ε}^{ε} φ((x − m₁)/s₁)/s₁ · [Φ((c − m₂)/s₂) − Φ((−c − m₂)/s₂)] dx``, ``c = √(ε² − x²)``.
The substitution ``x = ε sin θ`` removes the square-root endpoint singularity; adaptive
Gauss–Kronrod (``scipy.integrate.quad``) to an absolute error of 1e-12, with the Gaussian's peak as a
break point. A covariance whose larger deviation is below ``1e-12 ε`` is a point mass.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import quad
from scipy.special import ndtr

TOLERANCE = 1e-12


def disk_probability(mean: np.ndarray, covariance: np.ndarray, radius: float) -> float:
    """``P(‖z‖ ≤ radius)`` for ``z ~ N(mean, covariance)`` in two dimensions (eq. 5.39)."""
    w, v = np.linalg.eigh((np.asarray(covariance) + np.asarray(covariance).T) / 2)
    s2, s1 = np.sqrt(np.clip(w, 0.0, None))
    m2, m1 = v.T @ np.asarray(mean, dtype=float)
    if s1 <= 1e-12 * radius:
        return float(np.hypot(m1, m2) <= radius)
    inner_scale = max(s2, 1e-300)

    def integrand(theta: float) -> float:
        x, c = radius * np.sin(theta), radius * np.cos(theta)
        outer = np.exp(-0.5 * ((x - m1) / s1) ** 2) / (s1 * np.sqrt(2 * np.pi))
        return outer * (ndtr((c - m2) / inner_scale) - ndtr((-c - m2) / inner_scale)) * c

    peak = np.arcsin(np.clip(m1 / radius, -1.0, 1.0))
    breaks = [p for p in (peak,) if -np.pi / 2 < p < np.pi / 2]
    value, _ = quad(
        integrand, -np.pi / 2, np.pi / 2, points=breaks or None, epsabs=TOLERANCE, epsrel=1e-10, limit=200
    )
    return float(np.clip(value, 0.0, 1.0))


def capture_probabilities(means: np.ndarray, covariances: np.ndarray, radius: float) -> np.ndarray:
    """Eq. 5.39 at every step: ``means`` (N, 2), ``covariances`` (N, 2, 2) → (N,)."""
    return np.array([disk_probability(m, S, radius) for m, S in zip(means, covariances, strict=True)])
