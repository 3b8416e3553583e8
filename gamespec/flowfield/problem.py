"""A flow-field pursuit-evasion game, and the covariance game about its nominal paths, with every
value evaluated: what the numerics take."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from gamespec.flowfield.covariance_game import Feedforward, Payoff, PlayerBounds
from gamespec.flowfield.field import FlowField
from gamespec.flowfield.grid import Grid
from gamespec.flowfield.nominal import NominalPaths
from gamespec.flowfield.spec import FlowCovarianceGameSpec, FlowGameSpec, PlayerValues


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
        bounds=_bounds(v.players),
        speed_fraction=v.speed_fraction,
        capture_radius=v.capture_radius,
        step=v.step,
        payoff=v.payoff,
        feedforward=v.feedforward,
        grid=Grid(v.grid_lower, v.grid_upper, v.grid_nodes),
    )


def _bounds(players: tuple[PlayerValues, PlayerValues]) -> tuple[PlayerBounds, PlayerBounds]:
    return tuple(PlayerBounds(p.max_speed, p.delta_x, p.delta_u, p.beta) for p in players)


@dataclass(frozen=True)
class CovarianceGameData:
    """Section 5.3's game: the flow field, the starts ``origins`` (2, 2), the bounds, ε, the payoff,
    the feedforward rule, and the nominal paths with the number of steps ``N`` (None: no capture)."""

    field: FlowField
    origins: np.ndarray
    bounds: tuple[PlayerBounds, PlayerBounds]
    capture_radius: float
    payoff: Payoff
    feedforward: Feedforward
    paths: NominalPaths | None
    steps: int | None


def evaluate_game(
    spec: FlowCovarianceGameSpec, parameters: Mapping[str, float] | None = None
) -> CovarianceGameData:
    """The numerics' objects for the covariance game ``spec`` at its parameter values updated by
    ``parameters``; the nominal paths as the reachability stage wrote them."""
    v = spec.values(parameters)
    p = spec.problem
    paths = None
    if p.nominal is not None:
        n = p.nominal
        paths = NominalPaths(
            times=np.array(n.times, dtype=float),
            positions=np.array([n.pursuer.positions, n.evader.positions], dtype=float),
            directions=np.array([n.pursuer.directions, n.evader.directions], dtype=float),
            speeds=np.array(n.speeds, dtype=float),
        )
    return CovarianceGameData(
        field=FlowField(v.position, v.drift, v.diffusion),
        origins=np.array([q.initial for q in v.players], dtype=float),
        bounds=_bounds(v.players),
        capture_radius=v.capture_radius,
        payoff=p.payoff,
        feedforward=p.feedforward,
        paths=paths,
        steps=p.steps,
    )
