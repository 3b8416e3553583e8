"""Metrics of ``differential_game`` Results: what :mod:`gamespec.games.plotting` and
:mod:`gamespec.games.report` read (an open-loop game is drawn like an ``optimal_control`` Result,
so its metrics extend :class:`~gamespec.ocp.metrics.OcpMetrics`)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, PositiveFloat

from gamespec.metrics import array, known, shaped, state
from gamespec.ocp.metrics import OcpMetrics

if TYPE_CHECKING:
    from gamespec.result import Result


class Figure(BaseModel):
    """``metrics.figure`` of a receding-horizon run: which states are each player's position."""

    model_config = ConfigDict(extra="allow")

    obstacle_radius: PositiveFloat | None = Field(allow_inf_nan=False, description="r of the obstacle.")
    positions: dict[str, tuple[str, str]] = Field(description="Each player's (x, y) state names.")
    lookahead_players: dict[str, list[str]] = Field(
        description="Each viewing player's look-ahead: the players it simulates."
    )


class BestResponseRun(BaseModel):
    """One entry of ``metrics.best_response``: how an equilibrium iteration ended."""

    model_config = ConfigDict(extra="allow")

    scheme: str
    outcome: str
    iterations: int


class GameMetrics(OcpMetrics):
    """Metrics of a ``differential_game`` Result (open loop or receding horizon)."""

    figure: Figure | None = None
    best_response: dict[str, BestResponseRun] | None = None
    steps: int | None = Field(None, description="Receding-horizon steps taken.")
    captured: bool | None = None
    capture_time: float | None = None
    all_converged: bool | None = None

    def check(self, result: Result) -> None:
        if self.steps is not None and (self.captured is None or self.all_converged is None):
            raise ValueError("metrics.captured and metrics.all_converged are needed with metrics.steps")
        if self.captured and self.capture_time is None:
            raise ValueError("metrics.capture_time is missing for a captured run")
        if self.figure is None:
            super().check(result)
            return
        if result.time is None or result.control_time is None:
            raise ValueError("a receding-horizon Result needs time and control_time")
        time, steps = result.time, result.control_time
        if np.any(np.diff(time) < 0) or len(steps) == 0 or steps.max() > time[-1] or steps.min() < time[0]:
            raise ValueError("control_time does not lie on the time grid")
        for pair in self.figure.positions.values():
            known(pair, result.states, "metrics.figure.positions")
            for name in pair:
                state(result, name)
        for view in self.figure.lookahead_players:
            for name in self.figure.positions.get(view, ()):
                array(result, f"lookahead/{view}/{name}", 2, rows=len(steps))
        for key, values in result.arrays.items():
            parts = key.split("/")
            if parts[0] == "obstacle":
                if len(parts) != 3 or parts[2] not in ("x", "y"):
                    raise ValueError(f"arrays.{key} is not obstacle/NAME/x or obstacle/NAME/y")
                shaped(values, f"arrays.{key}", 1, rows=len(time))
                array(result, f"obstacle/{parts[1]}/{'y' if parts[2] == 'x' else 'x'}", 1, rows=len(time))
