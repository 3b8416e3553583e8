"""Metrics of ``optimal_control`` and ``multiphase_optimal_control`` Results, and of every Result
that falls back to their plots (an open-loop ``differential_game``): what
:mod:`gamespec.plotting`, the multi-phase summary and the desensitization and rcs figures read."""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydantic import BaseModel, ConfigDict, Field, PositiveFloat

from gamespec.desensitize.metrics import Desensitization, MonteCarlo
from gamespec.limits import MAX_EXPRESSION_CHARS
from gamespec.metrics import Finite, Metrics, known, shaped, state
from gamespec.rcs.metrics import Rcs, check_obstacles

if TYPE_CHECKING:
    from gamespec.result import Result


class Plot(BaseModel):
    """``metrics.plot``: the file's ``plot`` section and the path constraints drawn as circles."""

    model_config = ConfigDict(extra="allow")

    planar: list[tuple[str, str]] = Field(default_factory=list, description="Pairs drawn as paths.")
    units: dict[str, str] = Field(default_factory=dict, description="Unit of each name.")
    path_constraints: list[str] = Field(default_factory=list, description="Constraints drawn as circles.")
    angles: list[str] = Field(default_factory=list, description="Angles, drawn unwrapped.")


class Phase(BaseModel):
    """One entry of ``metrics.phases``: a phase's name and span."""

    model_config = ConfigDict(extra="allow")

    name: str
    start: Finite
    end: Finite


class OcpMetrics(Metrics):
    """Metrics of an ``optimal_control`` Result (and of what is drawn like one)."""

    plot: Plot | None = Field(None, description="What the figures draw, in which units.")
    phases: list[Phase] | None = Field(None, description="The phases of a multi-phase Result.")
    desensitization: Desensitization | None = Field(None, description="Chapter 6's desensitization.")
    monte_carlo: MonteCarlo | None = Field(None, description="Monte Carlo about the nominal path.")
    rcs: Rcs | None = Field(None, description="The rcs transform's relevance function.")
    obstacles: dict[str, PositiveFloat] | None = Field(None, description="Each obstacle's radius r_o.")
    obstacle_power: Finite | None = Field(None, description="β of eq. 6.41.")
    nominal_objective: float | None = Field(None, description="The original cost (desensitized).")
    sensitivity_measure: float | None = Field(None, description="The sensitivity measure.")

    def check(self, result: Result) -> None:
        for field in ("states", "controls"):
            for name, values in getattr(result, field).items():
                shaped(values, f"{field}.{name}", 1)
        planar = self.plot.planar if self.plot else []
        for pair in planar:
            known(pair, result.states, "metrics.plot.planar")
            for name in pair:
                state(result, name)
        for text in self.plot.path_constraints if self.plot else []:
            if len(text) > MAX_EXPRESSION_CHARS:
                raise ValueError("metrics.plot.path_constraints holds an over-long expression")
        if result.time is None and (result.states or result.controls):
            raise ValueError("trajectories without a time grid")
        if self.desensitization is not None and self.monte_carlo is not None:
            self.monte_carlo.check(result, planar)
        if self.rcs is not None:
            check_obstacles(result, self.obstacles or {})
