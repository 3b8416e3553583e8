"""The ``plot`` section of an ``optimal_control`` file: what its figures draw and in which units.

``planar`` lists the pairs of states that are positions in one plane (``[[xE, yE], [x1, y1]]``):
each pair becomes a path in the path figure, with the circular path constraints over it drawn as
disks. Without it no path figure is drawn (a plane is never guessed from state names). ``units``
labels axes: state, control or ``t`` names mapped to a unit such as ``m`` or ``s``.
"""

from __future__ import annotations

from pydantic import Field

from gamespec.specs.base import StrictModel


class PlotHint(StrictModel):
    """Planar pairs of states and axis units for the figures of an ``optimal_control`` Result."""

    planar: list[tuple[str, str]] = Field(
        default_factory=list, description="Pairs of states [x, y] that are positions in one plane."
    )
    units: dict[str, str] = Field(
        default_factory=dict, description="Unit of a state, a control or t, for axis labels (e.g. m, s)."
    )

    def as_metrics(self) -> dict[str, object]:
        """The JSON-able form a Result carries in ``metrics["plot"]``."""
        return {"planar": [list(pair) for pair in self.planar], "units": dict(self.units)}
