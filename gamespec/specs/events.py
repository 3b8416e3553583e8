"""Interior points of an ``optimal_control`` problem: constraints at a fixed time inside the horizon
(``at:``) and measured data (``measurements:``), both over the states' values at those times, the
parameters and the design variables (:mod:`gamespec.ocp.events` evaluates the states there by the
collocation polynomial of the interval that holds the time).
"""

from __future__ import annotations

from pydantic import Field, model_validator

from gamespec.specs.base import Number, StrictModel, Value


class EventSpec(StrictModel):
    """Constraints at one fixed time inside the horizon, such as ``x == 1`` at ``t = 5``: each
    constraint a relation over the states (their values at ``time``), the parameters and the design
    variables."""

    time: Value = Field(description="The time, a number or an expression of the parameters.")
    constraints: list[str] = Field(
        min_length=1, description="Relations over the states at that time, the parameters and design."
    )


class MeasurementsSpec(StrictModel):
    """Measured data: at each of ``times``, the value of each key of ``values`` (a state, or an
    expression over the states, the parameters and the design variables) was measured; the objective
    gains ``sum over keys and times of weight * (model - measured)**2`` (least squares), evaluated
    on the collocation polynomial at the measurement times."""

    times: list[Number] = Field(min_length=1, description="The measurement times, inside the horizon.")
    values: dict[str, list[Number]] = Field(
        min_length=1, description="Per measured state or expression, one value per time."
    )
    weights: dict[str, Number | list[Number]] = Field(
        default_factory=dict,
        description="Per key of values, a weight (or one per time) of its squared residuals; default 1.",
    )

    @model_validator(mode="after")
    def _one_value_per_time(self) -> MeasurementsSpec:
        n = len(self.times)
        for key, row in self.values.items():
            if len(row) != n:
                raise ValueError(f"values[{key!r}] has {len(row)} entries for {n} times")
        for key, weight in self.weights.items():
            if key not in self.values:
                raise ValueError(f"weights[{key!r}] names no key of values")
            if isinstance(weight, list) and len(weight) != n:
                raise ValueError(f"weights[{key!r}] has {len(weight)} entries for {n} times")
            if any(w < 0 for w in (weight if isinstance(weight, list) else [weight])):
                raise ValueError(f"weights[{key!r}] must be nonnegative")
        return self

    def weight_rows(self) -> dict[str, list[float]]:
        """Per key, one weight per time."""
        rows = {}
        for key in self.values:
            weight = self.weights.get(key, 1.0)
            rows[key] = (
                [float(w) for w in weight] if isinstance(weight, list) else [float(weight)] * len(self.times)
            )
        return rows
