"""Third-order TVD Runge–Kutta time stepping (Shu & Osher; Osher & Fedkiw eq. 3.9–3.11)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

Rate = Callable[[np.ndarray], np.ndarray]


def tvd_rk3_step(phi: np.ndarray, dt: float, rate: Rate) -> np.ndarray:
    """One step of size ``dt`` of ``φ_t = rate(φ)``, as convex combinations of forward Euler steps."""
    first = phi + dt * rate(phi)
    second = 0.75 * phi + 0.25 * (first + dt * rate(first))
    return phi / 3 + 2 / 3 * (second + dt * rate(second))


def step_sizes(duration: float, max_step: float) -> np.ndarray:
    """Equal steps no larger than ``max_step`` that add up to ``duration``."""
    count = max(1, int(np.ceil(duration / max_step - 1e-12)))
    return np.full(count, duration / count)
