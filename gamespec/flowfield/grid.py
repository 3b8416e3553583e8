"""A uniform two-dimensional grid of nodes, and bilinear interpolation on it."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True)
class Grid:
    """Nodes ``lower + i · spacing`` for ``i`` in ``[0, shape)`` along each of the two axes."""

    lower: tuple[float, float]
    upper: tuple[float, float]
    shape: tuple[int, int]

    @cached_property
    def spacing(self) -> np.ndarray:
        """Node spacing along each axis."""
        return (np.asarray(self.upper) - np.asarray(self.lower)) / (np.asarray(self.shape) - 1)

    @cached_property
    def axes(self) -> tuple[np.ndarray, np.ndarray]:
        """The node coordinates along each axis."""
        return tuple(
            np.linspace(lo, hi, n) for lo, hi, n in zip(self.lower, self.upper, self.shape, strict=True)
        )

    @cached_property
    def points(self) -> np.ndarray:
        """All nodes as an array (nx, ny, 2) (``ij`` indexing)."""
        return np.stack(np.meshgrid(*self.axes, indexing="ij"), axis=-1)

    def contains(self, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """Whether each point (..., 2) lies at least ``margin`` inside the grid's box."""
        lo, hi = np.asarray(self.lower) + margin, np.asarray(self.upper) - margin
        return np.all((points >= lo) & (points <= hi), axis=-1)

    def interpolate(self, values: np.ndarray, points: np.ndarray) -> np.ndarray:
        """Bilinear interpolation of node ``values`` (nx, ny, ...) at ``points`` (..., 2), clamped
        to the box."""
        scaled = (np.asarray(points) - np.asarray(self.lower)) / self.spacing
        top = np.asarray(self.shape) - 2
        cell = np.clip(np.floor(scaled).astype(int), 0, top)
        frac = np.clip(scaled - cell, 0.0, 1.0)
        i, j = cell[..., 0], cell[..., 1]
        a, b = frac[..., 0], frac[..., 1]
        shape = a.shape + (1,) * (values.ndim - 2)
        a, b = a.reshape(shape), b.reshape(shape)
        return (
            (1 - a) * (1 - b) * values[i, j]
            + a * (1 - b) * values[i + 1, j]
            + (1 - a) * b * values[i, j + 1]
            + a * b * values[i + 1, j + 1]
        )

    def gradient(self, values: np.ndarray) -> np.ndarray:
        """Second-order finite-difference gradient of node values (nx, ny) as (nx, ny, 2)."""
        return np.stack(np.gradient(values, *self.spacing, edge_order=2), axis=-1)
