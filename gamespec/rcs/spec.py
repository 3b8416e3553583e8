"""Options of the ``rcs`` and ``moving_obstacles`` transforms (thesis §6.4), as a file requests them:

```yaml
transforms:
  - moving_obstacles:                 # path constraints g <= 0 of eqs. 6.39 / 6.41 / 6.43-6.44
      agent: [x, y]                   # the agent's position (expressions of states)
      power: beta                     # β of eq. 6.41 (1: eq. 6.39)
      obstacles:
        o1: {center: [5, -1.25], velocity: [0, rho], radius: 2}
        train: {center: [5, -2], velocity: [0, rho], radius: 1, track: {half_width: 0.5, gamma: 20}}
  - rcs:                              # eqs. 6.31-6.36
      weight: Q                       # Q = weight·I (a list: one weight per constraint)
      relevance: logistic_derivative  # eq. 6.35 | gaussian | hat | logistic | inverse_quadratic
                                      # | inverse_abs_square | any expression of w
      relevant: true                  # false: the plain constraint-sensitivity penalty of eq. 6.32
      monte_carlo: {samples: 1000, seed: 0, steps: 500}
      cost_state: false               # true: the cost integrated as a state (its quadrature checked)
      restarts:                       # guess sections re-solved from when a solve fails a check
        - {states: {y: -3*sin(pi*tau)}}
```

Weights, radii, centres, velocities and β are numbers or expressions of the problem's parameters, so
``--set problem.parameters.Q=2`` re-solves the compiled model.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from pydantic import Field, field_validator

from gamespec.desensitize.spec import MonteCarloOptions
from gamespec.errors import ExpressionError, SpecError
from gamespec.specs.base import StrictModel, Value
from gamespec.specs.ocp import GuessSpec
from gamespec.symbolic.canonical import check


def check_values(
    parameters: Mapping[str, float], running: Iterable[str], items: list[tuple[str, Value]]
) -> None:
    """Each ``(field, value)`` an expression of the problem's ``parameters`` at their values and of
    the ``running`` names (states, controls, ``t``; none for a value of the parameters only), finite
    and real there: checked at load, so a bad centre or weight is one line naming its field, never
    an error of the transform or of a plot later."""
    running = list(running)
    for field, value in items:
        try:
            check(value, running, parameters)
        except ExpressionError as err:
            raise SpecError(str(err), field=field) from None


class RcsOptions(StrictModel):
    """The relevant-constraint-sensitivity cost ∫‖vec S_r‖²_Q (eq. 6.36) or ∫‖vec S_g‖²_Q (eq. 6.32)."""

    weight: Value | list[Value] = Field(
        1.0, description="Q = weight·I over the constraints, or one weight per constraint (diagonal Q)."
    )
    constraints: list[int] | None = Field(
        None, description="Indices of the inequality path constraints g <= 0 (default: all of them)."
    )
    relevance: str = Field("logistic_derivative", description="r̃ of eq. 6.33: a name or an expression of w.")
    relevant: bool = Field(True, description="Weight S_g by r(g) (eq. 6.34); false: eq. 6.32.")
    cost_state: bool = Field(
        False,
        description="Integrate the cost as a state (rcs_cost), so the defect estimate measures its "
        "quadrature error and method.refine refines where the risk is under-resolved (a steep "
        "integrand: car_vs_train); false: a Lagrange term, seen at the collocation points only.",
    )
    monte_carlo: MonteCarloOptions = Field(
        default_factory=MonteCarloOptions,
        description="The Monte Carlo estimate of the collision probability over the uncertain parameters.",
    )
    restarts: list[GuessSpec] = Field(
        default_factory=list,
        description="Other starting points (each a guess section of the problem) re-solved from when "
        "the first solution fails a check; the best one that passes every check is kept.",
    )

    def check_against(self, parameters: Mapping[str, float], running: Iterable[str], field: str) -> None:
        """The weights at the parameters' values (:func:`check_values`)."""
        weights = self.weight if isinstance(self.weight, list) else [self.weight]
        check_values(parameters, [], [(f"{field}.weight", w) for w in weights])


class Track(StrictModel):
    """The rail track of eq. 6.43: the obstacle runs along it; the super-Gaussian of eq. 6.44 (even
    ``gamma``) switches the constraint on while the agent is within ``half_width`` (w_o) of it."""

    half_width: Value = Field(description="The half width w_o within which the constraint is on.")
    gamma: int = Field(20, ge=2, le=200, description="The even exponent of the super-Gaussian of eq. 6.44.")

    @field_validator("gamma")
    @classmethod
    def _even(cls, v: int) -> int:
        if v % 2:
            raise ValueError("gamma must be even (eq. 6.44: γ ∈ 2Z+)")
        return v


class Obstacle(StrictModel):
    """A circular obstacle at ``center + velocity·(t - t0)`` with safe distance ``radius`` (r_o)."""

    center: tuple[Value, Value] = Field(
        description="The centre at t0: two numbers or expressions of the parameters."
    )
    velocity: tuple[Value, Value] = Field((0.0, 0.0), description="The constant velocity of the centre.")
    radius: Value = Field(description="The safe distance r_o.")
    track: Track | None = Field(None, description="Car-vs-train form (eq. 6.43), moving along y.")


class MovingObstaclesOptions(StrictModel):
    """Obstacles whose closed-form positions enter avoidance path constraints g <= 0."""

    agent: tuple[Value, Value] = Field(
        ("x", "y"), description="The agent's position: two state names or expressions."
    )
    power: Value = Field(1.0, description="β of eq. 6.41 (β = 1 is eq. 6.39); a number or parameter.")
    obstacles: dict[str, Obstacle] = Field(min_length=1, description="The obstacles, by name.")

    def check_against(self, parameters: Mapping[str, float], running: Iterable[str], field: str) -> None:
        """The agent's position over the ``running`` names, and β, the centres, velocities, radii and
        track widths at the parameters' values (:func:`check_values`)."""
        check_values(parameters, running, [(f"{field}.agent.{i}", a) for i, a in enumerate(self.agent)])
        items = [(f"{field}.power", self.power)]
        for name, o in self.obstacles.items():
            at = f"{field}.obstacles.{name}"
            items += [(f"{at}.center.{i}", c) for i, c in enumerate(o.center)]
            items += [(f"{at}.velocity.{i}", v) for i, v in enumerate(o.velocity)]
            items += [(f"{at}.radius", o.radius)]
            if o.track is not None:
                items += [(f"{at}.track.half_width", o.track.half_width)]
        check_values(parameters, [], items)
