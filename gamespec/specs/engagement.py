"""The ``engagement`` kind: pursuers and one evader in the plane (thesis ch. 2 and §3.2).

A user writes who is where, how fast, and how each pursuer chases (constant bearing ``cb``, pure
pursuit ``pp``, or ``stationary``); the reduced-state optimal-control problem of the evader (eqs.
2.8, 2.21, 2.34, 2.42, 3.2, 3.15–3.16) is generated from this by
:class:`gamespec.transforms.engagement.EngagementToOcp`, never typed by hand.

A stationary pursuer makes the engagement a relay pursuit (§2.5): exactly one pursuer is active and
the evader must stay out of every stationary pursuer's Voronoi cell (eq. 2.28).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from gamespec.registry import Kind
from gamespec.specs.base import Coordinate, Number, SpecBase, Speed, StrictModel
from gamespec.specs.ocp import MethodSpec

Strategy = Literal["cb", "pp", "stationary"]


class PursuerSpec(StrictModel):
    """One pursuer: its initial position, speed and navigation law.

    A stationary pursuer's speed is unused and may be 0; a moving one must outrun the evader (checked
    by :class:`EngagementSpec`, assumption A1), so it is > 0 there.
    """

    name: str = Field(description="Label used in reports and plots (P1, P2, ...).")
    position: tuple[Coordinate, Coordinate] = Field(description="The initial position [x, y].")
    speed: Speed = Field(1.0, description="Speed u_i; unused while the pursuer is stationary.")
    strategy: Strategy = Field(description="cb (constant bearing), pp (pure pursuit) or stationary.")


class EvaderSpec(StrictModel):
    """The evader: its initial position and speed v."""

    position: tuple[Coordinate, Coordinate] = Field(description="The initial position [x, y].")
    speed: Speed = Field(gt=0, description="The evader's speed v.")


class EngagementSpec(SpecBase):
    """Pursuers against one evader; the evader maximizes the capture time (kind ``engagement``).

    ``frame`` picks the reduced state: ``fixed`` (distances and line-of-sight angles in the inertial
    frame: eqs. 2.8, 2.34, 3.2, 3.15–3.16) or ``line_of_sight`` (the frame rotating with the first
    pursuer's line of sight, which must be pure pursuit: eqs. 2.21, 2.42). ``auto`` takes
    ``line_of_sight`` for two pursuers led by a pure-pursuit one, ``fixed`` otherwise.
    """

    kind: Literal["engagement"] = Field(
        "engagement", description="The problem kind; selects the schema of the rest of the file."
    )
    pursuers: list[PursuerSpec] = Field(min_length=1, description="The pursuers.")
    evader: EvaderSpec = Field(description="The evader.")
    capture_radius: Number = Field(0.001, gt=0, description="Capture radius ε.")
    frame: Literal["auto", "fixed", "line_of_sight"] = Field(
        "auto", description="The reduced state's frame: `fixed`, `line_of_sight` or `auto`."
    )
    method: MethodSpec = Field(
        default_factory=MethodSpec, description="The transcription of the lowered optimal-control problem."
    )
    guess_heading: Number | None = Field(
        None,
        description="Constant inertial-frame evader heading simulated to capture as the OCP's initial "
        "guess; default: the best constant heading (eq. 2.27 for pure pursuit), see gamespec.pursuit.guess.",
    )

    guess_fields = ("guess_heading",)

    def runtime_parameters(self) -> dict[str, float]:
        """Positions, speeds and the capture radius, by dotted path (``pursuers.1.speed``)."""
        values = {"capture_radius": self.capture_radius, "evader.speed": self.evader.speed}
        players = [("evader", self.evader), *((f"pursuers.{i}", p) for i, p in enumerate(self.pursuers))]
        for path, player in players:
            values |= {f"{path}.position.{k}": float(x) for k, x in enumerate(player.position)}
            values[f"{path}.speed"] = player.speed
        return values

    @property
    def objective_sense(self) -> str:
        """The evader maximizes the capture time."""
        return "maximize"

    @model_validator(mode="after")
    def _consistent(self) -> EngagementSpec:
        names = [p.name for p in self.pursuers]
        if len(set(names)) != len(names):
            raise ValueError(f"pursuer names must be unique, got {names}")
        active = self.active_indices
        if not active:
            raise ValueError("at least one pursuer must move (cb or pp)")
        if self.is_relay and len(active) != 1:
            raise ValueError("a relay engagement (a stationary pursuer) needs exactly one active pursuer")
        for i in active:
            if self.pursuers[i].speed <= self.evader.speed:
                raise ValueError(
                    f"pursuer {names[i]!r} must be faster than the evader (assumption A1): "
                    f"{self.pursuers[i].speed} <= {self.evader.speed}"
                )
        distance = {
            p.name: float(np.hypot(*np.subtract(p.position, self.evader.position))) for p in self.pursuers
        }
        for name, r in distance.items():
            if r <= self.capture_radius:
                raise ValueError(f"pursuer {name!r} starts inside the capture radius")
        if self.is_relay:
            r_active = distance[names[active[0]]]
            for p in self.pursuers:
                if p.strategy == "stationary" and distance[p.name] < r_active:
                    raise ValueError(
                        f"the evader starts inside the Voronoi cell of stationary pursuer {p.name!r} "
                        f"(eq. 2.28 at t = 0): it is {distance[p.name]:.6g} from it and {r_active:.6g} "
                        "from the active one"
                    )
        if self.frame == "line_of_sight" and self.pursuers[0].strategy != "pp":
            raise ValueError("frame line_of_sight rotates with the first pursuer, which must be pp")
        return self

    @property
    def active_indices(self) -> list[int]:
        """Indices of the pursuers that move (and can capture)."""
        return [i for i, p in enumerate(self.pursuers) if p.strategy != "stationary"]

    @property
    def is_relay(self) -> bool:
        """Whether a stationary pursuer guards its Voronoi cell (relay pursuit, §2.5)."""
        return any(p.strategy == "stationary" for p in self.pursuers)

    @property
    def resolved_frame(self) -> Literal["fixed", "line_of_sight"]:
        """The reduced-state frame after resolving ``auto``."""
        if self.frame != "auto":
            return self.frame
        lead_pp = self.pursuers[0].strategy == "pp"
        return "line_of_sight" if lead_pp and len(self.pursuers) == 2 else "fixed"


KIND = Kind(
    EngagementSpec,
    default_backend="casadi",
    plot="gamespec.pursuit.plotting:plot_engagement",
    summary="gamespec.pursuit.report:engagement_summary",
    metrics="gamespec.pursuit.metrics:EngagementMetrics",
    columns=(
        "metrics.capture_time",
        "metrics.capturing_set",
        "metrics.region",
    ),
)
"""The ``EngagementSpec`` kind as one plugin (:class:`~gamespec.registry.Kind`)."""
