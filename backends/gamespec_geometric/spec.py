"""The ``pursuit_scenario`` kind: a multi-pursuer multi-evader game in the plane (thesis §3.1–3.5).

Pursuers move with constant speeds ``u_i`` and follow constant bearing (``cb``, eq. 3.3) or pure
pursuit (``pp``); evaders move with constant speeds ``v_j`` and follow one of three strategies:
``blind`` evasion (a heading drawn at random from a set at every switching time, §3.3.2),
``pure_evasion`` (away from the nearest pursuer) or a ``fixed`` heading. Headings are numbers or
constant expressions such as ``-pi/4``. The scenario is simulated with time step ``time_step`` up
to ``horizon``; an evader is captured when a pursuer comes within ``capture_radius`` (eq. 3.5).
"""

from __future__ import annotations

from typing import Annotated, ClassVar, Literal

import numpy as np
from pydantic import (
    Field,
    ValidationError,
    ValidatorFunctionWrapHandler,
    field_validator,
    model_validator,
)

from gamespec.errors import ExpressionError, SpecError
from gamespec.limits import MAX_SIMULATION_VALUES
from gamespec.registry import Kind
from gamespec.specs.base import Coordinate, Number, SpecBase, Speed, StrictModel
from gamespec.symbolic.language import parse

Position = tuple[Coordinate, Coordinate]
PositiveFloat = Annotated[Number, Field(gt=0)]
PositiveSpeed = Annotated[Speed, Field(gt=0)]


def _constant(value: object) -> object:
    """A heading given as a constant expression (e.g. ``3*pi/4``) read into radians; other values are
    left to the field's type check."""
    if not isinstance(value, str):
        return value
    try:
        number = parse(value, {}).evalf()
    except ExpressionError as err:
        raise ValueError(str(err)) from None
    if not number.is_real or not number.is_finite:
        raise ValueError(f"heading {value!r} is not a finite real number")
    return float(number)


Heading = Annotated[
    float | str,
    Field(allow_inf_nan=False, description="Radians: a number or a constant expression like '-pi/4'."),
]
"""Read into a float by :func:`_constant` before validation."""


class FixedHeading(StrictModel):
    """A non-maneuvering evader: one heading for the whole game."""

    type: Literal["fixed"] = Field("fixed", description="`fixed`: one heading for the whole game.")
    heading: Heading

    @field_validator("heading", mode="before")
    @classmethod
    def _read(cls, value: object) -> object:
        return _constant(value)


class PureEvasion(StrictModel):
    """Run straight away from the nearest pursuer, re-aimed at every time step."""

    type: Literal["pure_evasion"] = Field(
        "pure_evasion", description="`pure_evasion`: run straight away from the nearest pursuer."
    )


class BlindEvasion(StrictModel):
    """Blind evasion with switching headings (§3.3.2): every ``switch_period`` a heading drawn from
    ``headings`` with a seeded random generator."""

    type: Literal["blind"] = Field("blind", description="`blind`: switch headings at random.")
    headings: list[Heading] = Field(min_length=1, description="The headings drawn from, in radians.")
    switch_period: PositiveFloat = Field(1.0, description="Time between heading switches.")
    seed: int = Field(0, ge=0, description="Seed of the random generator (a non-negative integer).")

    @field_validator("headings", mode="before")
    @classmethod
    def _read(cls, value: object) -> object:
        return [_constant(v) for v in value] if isinstance(value, list) else value


EvaderStrategy = Annotated[FixedHeading | PureEvasion | BlindEvasion, Field(discriminator="type")]


class Team(StrictModel):
    """Positions and speeds (one for all or one each) of one team; ``role`` names it in errors."""

    role: ClassVar[str]
    positions: list[Position] = Field(description="Initial positions [x, y], one per agent.")
    speed: PositiveSpeed | list[PositiveSpeed]

    @field_validator("positions")
    @classmethod
    def _not_empty(cls, value: list[Position]) -> list[Position]:
        if not value:
            raise ValueError(f"the {cls.role} team is empty: give at least one position")
        return value

    @field_validator("speed", mode="wrap")
    @classmethod
    def _positive(cls, value: object, handler: ValidatorFunctionWrapHandler) -> object:
        """One error at ``speed`` itself, not one per member of the union (``speed.constrained-float``)."""
        try:
            return handler(value)
        except ValidationError:
            raise ValueError(
                f"{cls.role} speed must be a positive number or a list of them, got {value!r}"
            ) from None

    def speeds(self) -> np.ndarray:
        """Speed of each member, ``(len(positions),)``."""
        return np.broadcast_to(np.asarray(self.speed, dtype=float), (len(self.positions),)).copy()


class PursuerTeam(Team):
    """Pursuer positions, speeds and pursuit strategies: ``cb`` or ``pp`` for the whole team, or a
    list with one per pursuer (a mixed team; its capture regions are all polygons, see
    :class:`gamespec_geometric.active.CaptureRegions`)."""

    role: ClassVar[str] = "pursuer"
    speed: PositiveSpeed | list[PositiveSpeed] = Field(
        1.0, description="The pursuers' speed: one for all, or a list with one per pursuer."
    )
    strategy: Literal["cb", "pp"] | list[Literal["cb", "pp"]] = Field(
        "cb",
        description="Pursuit law, `cb` (constant bearing) or `pp` (pure pursuit): one, or one per pursuer.",
    )

    def strategies(self) -> np.ndarray:
        """Strategy of each pursuer, ``(len(positions),)``."""
        return np.broadcast_to(np.asarray(self.strategy), (len(self.positions),)).copy()

    @property
    def team_strategy(self) -> str:
        """``cb`` or ``pp`` when every pursuer uses it, else ``mixed``."""
        kinds = set(self.strategies().tolist())
        return kinds.pop() if len(kinds) == 1 else "mixed"


class EvaderTeam(Team):
    """Evader positions, speeds and strategies (one for all or one each)."""

    role: ClassVar[str] = "evader"
    speed: PositiveSpeed | list[PositiveSpeed] = Field(
        0.6, description="The evaders' speed: one for all, or a list with one per evader."
    )
    strategy: EvaderStrategy | list[EvaderStrategy] = Field(
        default_factory=PureEvasion,
        description="The evaders' strategy (fixed, pure evasion or blind): one, or one per evader.",
    )

    def strategies(self) -> list[FixedHeading | PureEvasion | BlindEvasion]:
        """Strategy of each evader."""
        if isinstance(self.strategy, list):
            return list(self.strategy)
        return [self.strategy] * len(self.positions)


class PursuitScenarioSpec(SpecBase):
    """A multi-pursuer multi-evader scenario simulated with AVAA / A2 allocation (thesis chapter 3).

    ``allocation`` is ``avaa`` (§3.4, nearest-evader tie-break), ``a2`` (§3.5, soonest-capture
    tie-break) or ``auto`` (``avaa`` for homogeneous teams, ``a2`` otherwise).
    """

    kind: Literal["pursuit_scenario"] = Field(
        "pursuit_scenario", description="The problem kind; selects the schema of the rest of the file."
    )
    pursuers: PursuerTeam = Field(description="The pursuer team.")
    evaders: EvaderTeam = Field(description="The evader team.")
    capture_radius: PositiveFloat = Field(0.1, description="Distance at which a pursuer captures an evader.")
    time_step: PositiveFloat = Field(0.01, description="The simulation's time step.")
    horizon: PositiveFloat = Field(
        50.0, description="The simulated time after which the run stops (escapes are reported)."
    )
    allocation: Literal["auto", "avaa", "a2"] = Field(
        "auto",
        description="Task allocation: `avaa` (§3.4), `a2` (§3.5) or `auto` (avaa when homogeneous, else a2).",
    )

    def runtime_parameters(self) -> dict[str, float]:
        """The simulation's capture radius, time step and horizon (what a compiled scenario re-runs
        with)."""
        return {"capture_radius": self.capture_radius, "time_step": self.time_step, "horizon": self.horizon}

    @model_validator(mode="after")
    def _consistent(self) -> PursuitScenarioSpec:
        for team, field in ((self.pursuers, "pursuers"), (self.evaders, "evaders")):
            if isinstance(team.speed, list) and len(team.speed) != len(team.positions):
                raise SpecError(
                    f"{len(team.speed)} speeds for {len(team.positions)} positions", field=f"{field}.speed"
                )
        if isinstance(self.pursuers.strategy, list) and len(self.pursuers.strategy) != len(
            self.pursuers.positions
        ):
            raise SpecError(
                f"{len(self.pursuers.strategy)} strategies for {len(self.pursuers.positions)} pursuers",
                field="pursuers.strategy",
            )
        strategy = self.evaders.strategy
        if isinstance(strategy, list) and len(strategy) != len(self.evaders.positions):
            raise SpecError(
                f"{len(strategy)} strategies for {len(self.evaders.positions)} evaders",
                field="evaders.strategy",
            )
        slowest, fastest = self.pursuers.speeds().min(), self.evaders.speeds().max()
        if slowest <= fastest:
            raise SpecError(
                f"speeds violate eq. 3.29: the slowest pursuer ({slowest:g}) must be faster than the "
                f"fastest evader ({fastest:g})",
                field="pursuers.speed",
            )
        self._check_distinct()
        if self.time_step > self.horizon:
            raise SpecError("time_step must not exceed the horizon", field="time_step")
        recorded = (self.horizon / self.time_step + 1) * (
            len(self.pursuers.positions) + len(self.evaders.positions)
        )
        if recorded > MAX_SIMULATION_VALUES:
            raise SpecError(
                f"horizon / time_step × players = {recorded:.3g} recorded positions exceed the limit of "
                f"{MAX_SIMULATION_VALUES}: take a longer time_step or a shorter horizon",
                field="time_step",
            )
        return self

    def _check_distinct(self) -> None:
        """Coincident players make the Apollonius circles degenerate: refuse them by name."""
        players = np.array(self.pursuers.positions + self.evaders.positions, dtype=float)
        n = len(self.pursuers.positions)
        names = [f"pursuer {i}" for i in range(n)] + [f"evader {j}" for j in range(len(players) - n)]
        gaps = np.linalg.norm(players[:, None, :] - players[None, :, :], axis=2)
        gaps[np.diag_indices(len(players))] = np.inf
        same = np.argwhere(gaps <= 1e-12 * (1.0 + np.abs(players).max()))
        if len(same):
            a, b = same[0]
            field = "pursuers.positions" if b < n else "evaders.positions"
            where = tuple(players[a].tolist())
            raise SpecError(f"{names[a]} and {names[b]} coincide at {where}", field=field)

    @property
    def algorithm(self) -> Literal["avaa", "a2"]:
        """The allocation algorithm to run (``auto`` resolved by whether the teams are homogeneous)."""
        if self.allocation != "auto":
            return self.allocation
        homogeneous = np.ptp(self.pursuers.speeds()) == 0 and np.ptp(self.evaders.speeds()) == 0
        return "avaa" if homogeneous else "a2"


KIND = Kind(
    PursuitScenarioSpec,
    default_backend="geometric",
    plot="gamespec_geometric.plot:plot_scenario",
    summary="gamespec_geometric.report:scenario_summary",
    metrics="gamespec_geometric.metrics:ScenarioMetrics",
)
"""The ``PursuitScenarioSpec`` kind as one plugin (:class:`~gamespec.registry.Kind`)."""
