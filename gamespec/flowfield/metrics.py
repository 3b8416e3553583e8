"""Metrics of ``flow_field_game`` Results: what :mod:`gamespec.flowfield.plotting` and
:mod:`gamespec.flowfield.report` read (Theorem 6's capture time and point, eq. 5.39)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from pydantic import BaseModel, ConfigDict, Field

from gamespec.metrics import Finite, Metrics, array

if TYPE_CHECKING:
    from gamespec.result import Result

LOOPS = ("open_loop", "closed_loop", "lower_value", "minimax_mixed", "gauss_seidel")
"""The capture-probability series a Result may hold: open loop, the chosen concept's closed loop and
each solution concept of :mod:`gamespec.flowfield.concepts`."""


class Reachability(BaseModel):
    """``metrics.reachability``: the level sets read."""

    model_config = ConfigDict(extra="allow")

    levels: list[Finite] | None = Field(None, min_length=2, description="The levels; the second is drawn.")


class CaptureEstimate(BaseModel):
    """A Monte Carlo estimate of a capture probability with its interval."""

    model_config = ConfigDict(extra="allow")

    samples: int
    estimate: Finite
    low: Finite
    high: Finite


class FlowGameMetrics(Metrics):
    """Metrics of a ``flow_field_game`` Result."""

    capture_time: Finite | None = Field(None, description="T̂ (Theorem 6).")
    capture_point: tuple[Finite, Finite] | None = Field(None, description="x_f (Theorem 6).")
    reachability: Reachability | None = None
    monte_carlo_capture_probability: dict[str, CaptureEstimate] = Field(default_factory=dict)
    capture_probability_open_loop: float | None = None
    capture_probability_closed_loop: float | None = None
    capture_probability_lower_value: float | None = None
    capture_probability_minimax_mixed: float | None = None
    capture_probability_gauss_seidel: float | None = None
    game_converged: Any = None
    game_scheme: str | None = None

    def check(self, result: Result) -> None:
        if self.capture_time is not None and (
            self.capture_point is None or "game_converged" not in self.model_fields_set
        ):
            raise ValueError(
                "metrics.capture_point and metrics.game_converged are needed with a capture time"
            )
        if "nominal_positions" in result.arrays:
            if self.capture_time is None or self.reachability is None:
                raise ValueError("metrics.capture_time and metrics.reachability are needed with paths")
            array(result, "nominal_positions", 3, rows=2, last=2)
            if result.time is None:
                raise ValueError("a flow-field game Result without a time grid")
            for loop in LOOPS:
                if f"capture_probability_{loop}" in result.arrays:
                    array(result, f"capture_probability_{loop}", 1, rows=len(result.time) - 1)
            if "phi_final" in result.arrays:
                if self.reachability.levels is None:
                    raise ValueError("metrics.reachability.levels is missing")
                x, y = array(result, "grid_x", 1), array(result, "grid_y", 1)
                phi = array(result, "phi_final", 3, rows=2, last=len(y))
                if phi.shape[1] != len(x):
                    raise ValueError("arrays.phi_final does not match arrays.grid_x")
            elif "front_final" in result.arrays:
                array(result, "front_final", 3, rows=2, last=2)
        if "monte_carlo_closed_loop" in result.arrays:
            array(result, "monte_carlo_closed_loop", 3, last=4)
            array(result, "nominal_positions", 3, last=2)
