"""Third-order TVD Runge–Kutta time stepping (Shu & Osher; Osher & Fedkiw eq. 3.9–3.11), in place."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

StageRate = Callable[[int], np.ndarray]


def tvd_rk3_step(base: np.ndarray, first: np.ndarray, second: np.ndarray, dt: float, rate: StageRate) -> None:
    """One step of size ``dt`` of ``φ_t = L(φ)`` as convex combinations of forward Euler steps:
    ``φ¹ = φ + dt L(φ)``, ``φ² = ¾φ + ¼(φ¹ + dt L(φ¹))``, ``φ ← ⅓φ + ⅔(φ² + dt L(φ²))``.

    ``base``, ``first`` and ``second`` are the nodes being advanced of the state and of two stage
    arrays; ``rate(k)`` is ``L`` of stage ``k`` (0: the state, 1 and 2: the stage arrays) on those
    nodes, asked for after the stage's nodes are written; it may return a scratch array."""
    np.multiply(rate(0), dt, out=first)
    first += base
    r = rate(1)
    r *= dt
    r += first
    r *= 0.25
    np.multiply(base, 0.75, out=second)
    second += r
    r = rate(2)
    r *= dt
    r += second
    r *= 2 / 3
    base *= 1 / 3
    base += r
