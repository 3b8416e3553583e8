"""Samplers as inverse CDFs: each distribution turns ``dimension`` uniforms per draw into one value.

Drawing through the inverse CDF lets one stream of uniforms (plain or Latin hypercube, see
:mod:`gamespec.montecarlo.sampling`) serve every distribution alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np


def ndtri(u: np.ndarray) -> np.ndarray:
    """The standard normal's inverse CDF (SciPy's ``ndtri``), imported on first use: scipy.special
    costs a command's start-up ~0.2 s, and a file that samples nothing never calls it."""
    from scipy.special import ndtri as scipy_ndtri

    return np.asarray(scipy_ndtri(u))


@runtime_checkable
class Distribution(Protocol):
    """What :func:`gamespec.montecarlo.sample` needs of a distribution."""

    @property
    def shape(self) -> tuple[int, ...]:
        """Shape of one draw (``()`` for a scalar)."""
        ...

    @property
    def dimension(self) -> int:
        """Uniforms consumed per draw."""
        ...

    def from_uniform(self, u: np.ndarray) -> np.ndarray:
        """Draws ``(n, *shape)`` from uniforms ``u`` of shape ``(n, dimension)`` in the open (0, 1)."""
        ...


def _size(shape: tuple[int, ...]) -> int:
    return math.prod(shape)


@dataclass(frozen=True)
class Normal:
    """Independent normal entries ``mean + std · Φ⁻¹(u)``, one draw of shape ``shape``."""

    mean: float
    std: float
    shape: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        if not (math.isfinite(self.mean) and math.isfinite(self.std)) or self.std < 0:
            raise ValueError(f"Normal needs a finite mean and a finite std ≥ 0, got {self.mean}, {self.std}")

    @property
    def dimension(self) -> int:
        return _size(self.shape)

    def from_uniform(self, u: np.ndarray) -> np.ndarray:
        return (self.mean + self.std * ndtri(u)).reshape((u.shape[0], *self.shape))


@dataclass(frozen=True)
class Uniform:
    """Independent uniform entries on ``[low, high)``, one draw of shape ``shape``."""

    low: float
    high: float
    shape: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high)) or self.high < self.low:
            raise ValueError(f"Uniform needs finite low ≤ high, got {self.low}, {self.high}")

    @property
    def dimension(self) -> int:
        return _size(self.shape)

    def from_uniform(self, u: np.ndarray) -> np.ndarray:
        return (self.low + (self.high - self.low) * u).reshape((u.shape[0], *self.shape))


@dataclass(frozen=True, eq=False)
class MultivariateNormal:
    """A correlated normal vector ``mean + F z`` with ``F Fᵀ = covariance`` (a symmetric square root
    by eigendecomposition, so a singular covariance, e.g. a deterministic component, is allowed)."""

    mean: np.ndarray
    covariance: np.ndarray
    factor: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        mean = np.asarray(self.mean, dtype=float).reshape(-1)
        cov = np.asarray(self.covariance, dtype=float)
        if cov.shape != (mean.size, mean.size) or not np.allclose(cov, cov.T):
            raise ValueError(f"covariance must be a symmetric {mean.size}×{mean.size} matrix")
        eigenvalues, vectors = np.linalg.eigh(cov)
        floor = -1e-10 * max(1.0, float(np.max(np.abs(eigenvalues), initial=0.0)))
        if np.any(eigenvalues < floor):
            raise ValueError("covariance must be positive semidefinite")
        object.__setattr__(self, "mean", mean)
        object.__setattr__(self, "covariance", cov)
        object.__setattr__(self, "factor", vectors * np.sqrt(np.clip(eigenvalues, 0.0, None)))

    @property
    def shape(self) -> tuple[int, ...]:
        return (self.mean.size,)

    @property
    def dimension(self) -> int:
        return self.mean.size

    def from_uniform(self, u: np.ndarray) -> np.ndarray:
        return self.mean + ndtri(u) @ self.factor.T
