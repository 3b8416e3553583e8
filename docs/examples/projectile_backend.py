"""A new backend: the projectile of ``projectile_kind.py`` in closed form.

A backend declares its kinds and an options model (validated from ``solver.options.ballistic``),
compiles a spec once and solves the compiled model as often as asked, returning a Result.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from pydantic import Field

from gamespec import registry
from gamespec.compiling import Backend, CompiledModel, Inputs, refuse_inputs
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel


class BallisticOptions(StrictModel):
    """Options of the ballistic backend."""

    samples: int = Field(101, ge=2, description="Points on the returned trajectory.")


class BallisticModel(CompiledModel):
    """The flight of one projectile: t_f = 2 v sin(a)/g, range v² sin(2a)/g."""

    def __init__(self, spec, options: BallisticOptions) -> None:
        self.spec, self.options = spec, options

    def solve(self, parameters=None, guess: Result | None = None, inputs: Inputs = None) -> Result:
        refuse_inputs(inputs, self.spec.kind)
        v, a, g = self.spec.speed, np.radians(self.spec.angle), self.spec.gravity
        t_f = 2 * v * np.sin(a) / g
        t = np.linspace(0.0, t_f, self.options.samples)
        x, y = v * np.cos(a) * t, v * np.sin(a) * t - 0.5 * g * t**2
        return Result(
            status=Status.OPTIMAL,
            message="closed form",
            objective=float(x[-1]),
            t_final=float(t_f),
            time=t,
            states={"x": x, "y": y},
            metrics={"range": float(x[-1])},
        )


class BallisticBackend(Backend):
    """Closed-form projectile flight."""

    name: ClassVar[str] = "ballistic"
    kinds: ClassVar[frozenset[str]] = frozenset({"projectile"})
    options_model: ClassVar[type[StrictModel]] = BallisticOptions

    def _compile(self, spec, options: BallisticOptions) -> BallisticModel:
        return BallisticModel(spec, options)


registry.register("gamespec.backends", "ballistic", BallisticBackend)
