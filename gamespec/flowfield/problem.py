"""A flow-field pursuit-evasion game with every value evaluated: what the numerics take."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from gamespec.flowfield.covariance_game import Feedforward, Payoff, PlayerBounds
from gamespec.flowfield.field import FlowField
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.spec import FlowGameSpec


@dataclass(frozen=True)
class FlowGameData:
    """Eqs. 5.1–5.3 and the parameters of section 5.4: the flow field, the agents' starts
    ``origins`` (2, 2) (pursuer, evader), their bounds, the nominal speed fraction ``v̂/v_max``, the
    capture radius ε, the step ``T̂/N``, the payoff, the feedforward rule and the reachability grid."""

    field: FlowField
    origins: np.ndarray
    bounds: tuple[PlayerBounds, PlayerBounds]
    speed_fraction: float
    capture_radius: float
    step: float
    payoff: Payoff
    feedforward: Feedforward
    grid: Grid

    @property
    def nominal_speeds(self) -> np.ndarray:
        """``v̂ⁱ = fraction · vⁱ_max`` (eq. 5.24, 5.26)."""
        return self.speed_fraction * np.array([b.max_speed for b in self.bounds])


def evaluate(spec: FlowGameSpec, parameters: Mapping[str, float] | None = None) -> FlowGameData:
    """The numerics' objects for ``spec`` at its parameter values updated by ``parameters``."""
    v = spec.values(parameters)
    return FlowGameData(
        field=FlowField(v.position, v.drift, v.diffusion),
        origins=np.array([p.initial for p in v.players], dtype=float),
        bounds=tuple(PlayerBounds(p.max_speed, p.delta_x, p.delta_u, p.beta) for p in v.players),
        speed_fraction=v.speed_fraction,
        capture_radius=v.capture_radius,
        step=v.step,
        payoff=v.payoff,
        feedforward=v.feedforward,
        grid=Grid(v.grid_lower, v.grid_upper, v.grid_nodes),
    )
