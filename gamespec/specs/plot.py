"""The ``plot`` section of an ``optimal_control`` file: what its figures draw and in which units.

``planar`` lists the pairs of states that are positions in one plane (``[[xE, yE], [x1, y1]]``):
each pair becomes a path in the path figure, with the circular path constraints over it drawn as
disks. Without it no path figure is drawn (a plane is never guessed from state names). ``units``
labels axes: state, control or ``t`` names mapped to a unit such as ``m`` or ``s``. ``angles`` names
the states and controls that are angles in radians (a heading that enters the problem only through
``cos`` and ``sin``): they are drawn unwrapped (continuous modulo 2π, :func:`numpy.unwrap`), so that
a heading of 4.24 next to one of −2.04 (the same direction) is not drawn as a jump.

The ``differential_game`` kind has the same section (its controls are every player's).
"""

from __future__ import annotations

from pydantic import Field

from gamespec.errors import SpecError
from gamespec.specs.base import StrictModel


class PlotHint(StrictModel):
    """Planar pairs of states and axis units for the figures of an ``optimal_control`` Result."""

    planar: list[tuple[str, str]] = Field(
        default_factory=list, description="Pairs of states [x, y] that are positions in one plane."
    )
    units: dict[str, str] = Field(
        default_factory=dict, description="Unit of a state, a control or t, for axis labels (e.g. m, s)."
    )
    angles: list[str] = Field(
        default_factory=list,
        description="States and controls that are angles in radians, drawn unwrapped (continuous mod 2π).",
    )

    def check_names(self, states: list[str], controls: list[str]) -> None:
        """A SpecError naming the ``plot`` field that names no state (planar), or no state, control
        or ``t`` (units; no state or control: angles)."""
        for i, pair in enumerate(self.planar):
            unknown = [n for n in pair if n not in states]
            if unknown:
                raise SpecError(f"{', '.join(unknown)} is not a state", field=f"plot.planar.{i}")
        named = {*states, *controls}
        for name in self.units:
            if name not in named | {"t"}:
                raise SpecError(f"{name!r} is not a state, a control or t", field=f"plot.units.{name}")
        for i, name in enumerate(self.angles):
            if name not in named:
                raise SpecError(f"{name!r} is not a state or a control", field=f"plot.angles.{i}")

    def as_metrics(self) -> dict[str, object]:
        """The JSON-able form a Result carries in ``metrics["plot"]``."""
        return {
            "planar": [list(pair) for pair in self.planar],
            "units": dict(self.units),
            "angles": list(self.angles),
        }
