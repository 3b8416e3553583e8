"""The Hamiltonian of forward reachability in a flow field, eq. 5.22, with Lax–Friedrichs dissipation.

``φ_t + H(x, ∇φ) = 0`` with ``H(x, p) = v̂ |p| + p · f(x)``. The numerical Hamiltonian is the local
Lax–Friedrichs one (Osher & Fedkiw eq. 5.9) on the upwind pair ``(p⁻, p⁺)`` of each axis:
``Ĥ = H(x, p̄) − Σ_i α_i j_i/2`` with ``p̄ = (p⁻ + p⁺)/2``, the jumps ``j = p⁺ − p⁻`` and
``α_i(x) = v̂ + |f_i(x)| ≥ |∂H/∂p_i|``. With that α and ``p̄ = p⁺ − j/2`` it is evaluated as
``Ĥ = v̂ |p̄| + Σ_i (f_i p_i⁺ − (f_i⁺ + v̂/2) j_i)`` (``f⁺ = max(f, 0)``; the drift's part is upwind
advection, ``f⁺ p⁻ + f⁻ p⁺``): the drift is tabulated on the grid and split once, and each
evaluation reads it on the rectangle of nodes being updated, in place.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

Window = tuple[slice, slice]


@dataclass(frozen=True)
class FlowHamiltonian:
    """``H`` for agents with nominal speeds ``speeds`` (one per leading slice of φ) in a drift
    ``drift`` tabulated on the grid (nx, ny, 2)."""

    speeds: np.ndarray
    drift: np.ndarray

    @cached_property
    def flow(self) -> np.ndarray:
        """``f`` as (2, nx, ny), C-contiguous per component."""
        return np.ascontiguousarray(np.moveaxis(np.asarray(self.drift, dtype=float), -1, 0))

    @cached_property
    def jump_weights(self) -> np.ndarray:
        """``f⁺ + v̂/2`` per agent and component, (agents, 2, nx, ny)."""
        speeds = np.asarray(self.speeds, dtype=float).reshape(-1, 1, 1, 1)
        return np.maximum(self.flow, 0.0)[None] + speeds / 2

    def numerical(
        self,
        agent: int,
        window: Window,
        minus: tuple[np.ndarray, np.ndarray],
        plus: tuple[np.ndarray, np.ndarray],
        out: tuple[np.ndarray, np.ndarray],
    ) -> np.ndarray:
        """The local Lax–Friedrichs ``Ĥ`` of ``agent`` on the nodes ``window`` from the upwind pairs
        of both axes (each shaped like the window), into ``out[0]`` (``out[1]`` is scratch of the
        same shape); ``minus`` and ``plus`` are overwritten."""
        (mx, my), (px, py), (h, work) = minus, plus, out
        speed = float(np.asarray(self.speeds, dtype=float)[agent])
        f, weights = self.flow, self.jump_weights[agent]
        np.subtract(px, mx, out=mx)
        np.subtract(py, my, out=my)
        np.multiply(mx, -0.5, out=h)
        h += px
        np.square(h, out=h)
        np.multiply(my, -0.5, out=work)
        work += py
        np.square(work, out=work)
        h += work
        np.sqrt(h, out=h)  # |p̄| (np.hypot, guarding against overflow, is several times slower)
        h *= speed
        for p, jump, axis in ((px, mx, 0), (py, my, 1)):
            np.multiply(p, f[axis][window], out=p)
            h += p
            np.multiply(jump, weights[axis][window], out=jump)
            h -= jump
        return h

    def max_step(self, spacing: np.ndarray, cfl: float) -> float:
        """The CFL-limited time step ``cfl / max(α_x/dx + α_y/dy)``."""
        alpha = np.max(np.asarray(self.speeds, dtype=float)) + np.abs(self.flow)
        return float(cfl / np.max(alpha[0] / spacing[0] + alpha[1] / spacing[1]))
