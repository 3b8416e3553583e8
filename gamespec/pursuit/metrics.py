"""Metrics of ``engagement`` Results: what :mod:`gamespec.pursuit.plotting` and the engagement
summary read."""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from gamespec.metrics import Finite, Metrics, array
from gamespec.specs.engagement import EngagementSpec

if TYPE_CHECKING:
    from gamespec.result import Result


class Arcs(BaseModel):
    """``metrics.arcs`` of a relay engagement (eqs. 2.41, 2.46)."""

    model_config = ConfigDict(extra="allow")

    tau1: Finite
    tau2: Finite
    interior_duration: Finite
    boundary_duration: Finite
    line_of_sight_duration: Finite
    switching_residual: float | None


class EngagementMetrics(Metrics):
    """Metrics of an ``engagement`` Result (:func:`gamespec.pursuit.report.engagement_report`)."""

    capture_time: float | None = Field(None, description="The capture time t_c.")
    capturing_set: list[str] = Field(default_factory=list, description="P* (Definition 2).")
    simultaneous_capture_gap: float | None = None
    terminal_distances: dict[str, float | None] = Field(default_factory=dict)
    region: str | None = Field(None, description="D1, D2 or N (§2.3) of P2.")
    initial_heading: float | None = None
    arcs: Arcs | Annotated[dict[str, Any], Field(max_length=0)] | None = Field(
        None, description="Relay arcs (an empty mapping: none)."
    )
    engagement: dict[str, Any] | None = Field(
        None, description="The players and the capture radius (an engagement spec's fields)."
    )

    def spec(self) -> EngagementSpec:
        """The engagement the Result is of (ValueError when there is none or it is not one)."""
        if self.engagement is None:
            raise ValueError("metrics.engagement is missing")
        try:
            return EngagementSpec.model_validate(self.engagement)
        except ValidationError as err:
            first = err.errors()[0]
            where = ".".join(str(p) for p in ("metrics.engagement", *first["loc"]))
            raise ValueError(f"{where}: {' '.join(first['msg'].split())}") from None

    def check(self, result: Result) -> None:
        if self.engagement is not None:
            self.spec()
        if "path_evader" not in result.arrays:
            return
        spec = self.spec()
        if result.t_final is None:
            raise ValueError("an engagement Result with paths has no t_final")
        time = array(result, "path_time", 1)
        array(result, "path_evader", 2, rows=len(time), last=2)
        for pursuer in spec.pursuers:
            array(result, f"path_{pursuer.name}", 2, rows=len(time), last=2)
        for name in result.arrays:
            if name.startswith("path_") and name != "path_time":
                array(result, name, 2, last=2)
