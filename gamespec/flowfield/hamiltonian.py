"""The Hamiltonian of forward reachability in a flow field, eq. 5.22, with Lax–Friedrichs dissipation.

``φ_t + H(x, ∇φ) = 0`` with ``H(x, p) = v̂ |p| + p · f(x)``. The numerical Hamiltonian is the local
Lax–Friedrichs one (Osher & Fedkiw eq. 5.9) on the upwind pair ``(p⁻, p⁺)`` of each axis:
``Ĥ = H(x, (p⁻ + p⁺)/2) − Σ_i α_i (p_i⁺ − p_i⁻)/2`` with ``α_i(x) = v̂ + |f_i(x)| ≥ |∂H/∂p_i|``.
The drift is tabulated on the grid once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class FlowHamiltonian:
    """``H`` for agents with nominal speeds ``speeds`` (one per leading slice of φ) in a drift
    ``drift`` tabulated on the grid (nx, ny, 2)."""

    speeds: np.ndarray
    drift: np.ndarray

    def _speed(self, ndim: int) -> np.ndarray:
        return np.asarray(self.speeds, dtype=float).reshape((-1,) + (1,) * (ndim - 1))

    def value(self, p: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
        """``H(x, p)`` at every node; each component of ``p`` has shape (agents, nx, ny)."""
        px, py = p
        return self._speed(px.ndim) * np.hypot(px, py) + px * self.drift[..., 0] + py * self.drift[..., 1]

    def dissipation(self, ndim: int) -> tuple[np.ndarray, np.ndarray]:
        """``α_i = v̂ + |f_i|`` per agent and node, for each axis."""
        speed = self._speed(ndim)
        return speed + np.abs(self.drift[..., 0]), speed + np.abs(self.drift[..., 1])

    def numerical(
        self, minus: tuple[np.ndarray, np.ndarray], plus: tuple[np.ndarray, np.ndarray]
    ) -> np.ndarray:
        """The local Lax–Friedrichs ``Ĥ`` from the upwind pairs of both axes."""
        mean = ((minus[0] + plus[0]) / 2, (minus[1] + plus[1]) / 2)
        ax, ay = self.dissipation(minus[0].ndim)
        return self.value(mean) - ax * (plus[0] - minus[0]) / 2 - ay * (plus[1] - minus[1]) / 2

    def max_step(self, spacing: np.ndarray, cfl: float) -> float:
        """The CFL-limited time step ``cfl / max(α_x/dx + α_y/dy)``."""
        ax, ay = self.dissipation(3)
        return float(cfl / np.max(ax / spacing[0] + ay / spacing[1]))
