"""A flow-field pursuit-evasion game with every value evaluated: what the numerics take."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gamespec.flowfield.covariance_game import Payoff, PlayerBounds
from gamespec.flowfield.field import FlowField
from gamespec.flowfield.grid import Grid


@dataclass(frozen=True)
class FlowGameData:
    """Eqs. 5.1–5.3 and the parameters of section 5.4: the flow field, the agents' starts
    ``origins`` (2, 2) (pursuer, evader), their bounds, the nominal speed fraction ``v̂/v_max``, the
    capture radius ε, the step ``T̂/N``, the payoff and the reachability grid."""

    field: FlowField
    origins: np.ndarray
    bounds: tuple[PlayerBounds, PlayerBounds]
    speed_fraction: float
    capture_radius: float
    step: float
    payoff: Payoff
    grid: Grid

    @property
    def nominal_speeds(self) -> np.ndarray:
        """``v̂ⁱ = fraction · vⁱ_max`` (eq. 5.24, 5.26)."""
        return self.speed_fraction * np.array([b.max_speed for b in self.bounds])
