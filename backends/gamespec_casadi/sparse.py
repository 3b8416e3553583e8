"""Constant sparse matrices in NumPy triplets for the CasADi build, without SciPy (whose import
would cost start-up time on every solve): Kronecker products, stacking, compressed columns and the
conversion to a ``casadi.DM`` with duplicate entries summed."""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np


@dataclass(frozen=True)
class Coo:
    """A sparse matrix as entries ``(rows[n], cols[n]) += values[n]``; duplicates add up."""

    rows: np.ndarray
    cols: np.ndarray
    values: np.ndarray
    shape: tuple[int, int]

    @classmethod
    def of(cls, rows, cols, values, shape: tuple[int, int]) -> Coo:
        """From anything array-like (e.g. :attr:`~gamespec.ocp.collocation.Grid.triplets`)."""
        rows, cols = (np.asarray(v, dtype=np.int64).ravel() for v in (rows, cols))
        values = np.broadcast_to(np.asarray(values, dtype=float), rows.shape).ravel()
        return cls(rows, cols, values, (int(shape[0]), int(shape[1])))

    @classmethod
    def eye(cls, n_rows: int, n_cols: int, offset: int = 0) -> Coo:
        """Ones at ``(i, i + offset)``."""
        i = np.arange(max(0, min(n_rows, n_cols - offset)))
        return cls.of(i, i + offset, 1.0, (n_rows, n_cols))

    def kron(self, other: Coo) -> Coo:
        """The Kronecker product ``self ⊗ other``."""
        (m, n), (p, q) = self.shape, other.shape
        rows = (self.rows[:, None] * p + other.rows[None, :]).ravel()
        cols = (self.cols[:, None] * q + other.cols[None, :]).ravel()
        return Coo.of(rows, cols, (self.values[:, None] * other.values[None, :]).ravel(), (m * p, n * q))

    def resized(self, shape: tuple[int, int]) -> Coo:
        """The same entries in a larger matrix (zero rows and columns added after)."""
        return Coo(self.rows, self.cols, self.values, shape)

    @staticmethod
    def vstack(blocks: list[Coo]) -> Coo:
        """Blocks (of one width) one below the other."""
        offsets = np.cumsum([0] + [b.shape[0] for b in blocks])
        return Coo.of(
            np.concatenate([b.rows + o for b, o in zip(blocks, offsets, strict=False)]),
            np.concatenate([b.cols for b in blocks]),
            np.concatenate([b.values for b in blocks]),
            (int(offsets[-1]), blocks[0].shape[1]),
        )

    def compressed_columns(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(colind, row, values)`` in CasADi's (and CSC's) order, duplicates summed."""
        keys = self.cols * self.shape[0] + self.rows
        order = np.argsort(keys, kind="stable")
        keys = keys[order]
        first = np.diff(keys, prepend=-1) != 0
        values = np.add.reduceat(self.values[order], np.flatnonzero(first)) if keys.size else self.values
        unique = keys[first]
        counts = np.bincount(unique // self.shape[0], minlength=self.shape[1])
        return np.concatenate([[0], np.cumsum(counts)]), unique % self.shape[0], values

    def dm(self) -> ca.DM:
        """As a sparse ``casadi.DM`` (from compressed columns: several times faster than triplets)."""
        colind, row, values = self.compressed_columns()
        pattern = ca.Sparsity(*self.shape, colind.tolist(), row.tolist())
        return ca.DM(pattern, values.tolist())
