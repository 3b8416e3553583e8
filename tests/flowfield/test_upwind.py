"""The in-place WENO5 (Jiang–Peng form) against the textbook weighted stencils, and the split
local Lax–Friedrichs Hamiltonian against its definition (eq. 5.22)."""

from __future__ import annotations

import numpy as np
import pytest

from gamespec.flowfield.hamiltonian import FlowHamiltonian
from gamespec.flowfield.scratch import Scratch
from gamespec.flowfield.upwind import GHOSTS, WENO_EPSILON, extrapolate_ghosts, upwind_pair


def _textbook_weno5(phi: np.ndarray, dx: float) -> tuple[np.ndarray, np.ndarray]:
    """Osher & Fedkiw eqs. 3.28–3.39 along axis 0 of a padded column: the three ENO stencils
    ``φ¹, φ², φ³`` weighted by ``ωₖ ∝ γₖ / (Sₖ + ε)²``, for D⁻ (``v₁ … v₅`` = differences at
    i − 5/2 … i + 3/2) and D⁺ (the same read backwards from i + 5/2)."""
    d = np.diff(phi, axis=0) / dx
    n = phi.shape[0] - 2 * GHOSTS

    def weighted(v1, v2, v3, v4, v5):
        stencils = (
            v1 / 3 - 7 * v2 / 6 + 11 * v3 / 6,
            -v2 / 6 + 5 * v3 / 6 + v4 / 3,
            v3 / 3 + 5 * v4 / 6 - v5 / 6,
        )
        smooth = (
            13 / 12 * (v1 - 2 * v2 + v3) ** 2 + (v1 - 4 * v2 + 3 * v3) ** 2 / 4,
            13 / 12 * (v2 - 2 * v3 + v4) ** 2 + (v2 - v4) ** 2 / 4,
            13 / 12 * (v3 - 2 * v4 + v5) ** 2 + (3 * v3 - 4 * v4 + v5) ** 2 / 4,
        )
        eps = WENO_EPSILON * np.max([v1**2, v2**2, v3**2, v4**2, v5**2], axis=0) + 1e-99
        alpha = [g / (s + eps) ** 2 for g, s in zip((0.1, 0.6, 0.3), smooth, strict=True)]
        return sum(a * p for a, p in zip(alpha, stencils, strict=True)) / sum(alpha)

    left = weighted(*(d[k : k + n] for k in range(5)))
    right = weighted(*(d[k : k + n] for k in range(5, 0, -1)))
    return left, right


@pytest.mark.parametrize("axis", [0, 1])
def test_weno5_matches_the_weighted_stencils(axis: int) -> None:
    """Smooth, kinked and noisy data on a padded block, either axis: the same numbers to rounding."""
    rng = np.random.default_rng(7)
    x, y = np.meshgrid(np.linspace(-2, 2, 37), np.linspace(-1, 3, 29), indexing="ij")
    dx = (x[1, 0] - x[0, 0], y[0, 1] - y[0, 0])[axis]
    for phi in (np.hypot(x - 0.3, y - 1.1), np.abs(x + 0.1) + np.sin(y), rng.normal(size=x.shape)):
        padded = np.zeros((x.shape[0] + 2 * GHOSTS, x.shape[1] + 2 * GHOSTS))
        padded[GHOSTS:-GHOSTS, GHOSTS:-GHOSTS] = phi
        extrapolate_ghosts(padded)
        inner = slice(GHOSTS, -GHOSTS)
        block = padded[:, inner] if axis == 0 else padded[inner, :]
        left, right = upwind_pair(block, axis, dx, "weno5", Scratch(padded.size))
        column = block if axis == 0 else block.T
        expected = [e if axis == 0 else e.T for e in _textbook_weno5(column, dx)]
        scale = np.abs(np.diff(column, axis=0)).max() / dx
        np.testing.assert_allclose(left, expected[0], rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(right, expected[1], rtol=0, atol=1e-12 * scale)


def test_split_hamiltonian_is_local_lax_friedrichs() -> None:
    """``v̂|p̄| + p̄·f − Σ (v̂ + |f_i|)(p_i⁺ − p_i⁻)/2`` on random pairs, a window of the grid."""
    rng = np.random.default_rng(3)
    drift = rng.normal(size=(9, 8, 2))
    speeds = np.array([1.7, 0.6])
    window = (slice(2, 7), slice(1, 5))
    shape = (5, 4)
    minus, plus = rng.normal(size=(2, *shape)), rng.normal(size=(2, *shape))
    f = drift[window]
    for agent, speed in enumerate(speeds):
        mean = (minus + plus) / 2
        expected = speed * np.hypot(*mean) + mean[0] * f[..., 0] + mean[1] * f[..., 1]
        for i in range(2):
            expected -= (speed + np.abs(f[..., i])) * (plus[i] - minus[i]) / 2
        out = (np.empty(shape), np.empty(shape))
        got = FlowHamiltonian(speeds, drift).numerical(
            agent, window, tuple(minus.copy()), tuple(plus.copy()), out
        )
        np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-13)
