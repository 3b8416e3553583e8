"""A new transform: lower a projectile to an ``optimal_control`` spec, so that every OCP backend
(casadi, pyomo) solves it by collocation, and map the Result back.

``apply`` is pure and returns the new spec with what ``invert`` needs; ``invert`` never solves.
The generated spec only names declared symbols and numbers (no expression text is assembled).
"""

from __future__ import annotations

import math
from typing import Any, ClassVar

from gamespec import registry
from gamespec.loader import spec_from_dict
from gamespec.result import Result
from gamespec.specs.base import StrictModel
from gamespec.transforms.base import Transform


class ProjectileToOcp(Transform):
    """projectile → optimal_control: states x, y, vx, vy over the closed-form flight time."""

    name: ClassVar[str] = "projectile_to_ocp"
    source_kind: ClassVar[str] = "projectile"
    target_kind: ClassVar[str] = "optimal_control"
    requested: ClassVar[bool] = False

    def apply(self, spec, options: StrictModel, upstream: Result | None = None):
        a = math.radians(spec.angle)
        vx, vy = spec.speed * math.cos(a), spec.speed * math.sin(a)
        ocp = {
            "kind": "optimal_control",
            "name": spec.name,
            "problem": {
                "states": {
                    "x": {"initial": 0.0},
                    "y": {"initial": 0.0},
                    "vx": {"initial": vx},
                    "vy": {"initial": vy},
                },
                "dynamics": {"x": "vx", "y": "vy", "vx": 0.0, "vy": -spec.gravity},
                "objective": {"sense": "maximize", "mayer": "x_f"},
                "time": {"final": 2 * vy / spec.gravity},
            },
            "method": {"intervals": 10, "degree": 3},
            "plot": {"planar": [["x", "y"]]},
        }
        return spec_from_dict(ocp, source=spec.source), None

    def invert(self, result: Result, spec, inverse_data: Any) -> Result:
        states = {k: result.states[k] for k in ("x", "y")}
        metrics = {"range": float(states["x"][-1])}
        return result.model_copy(
            update={"kind": spec.kind, "problem": spec.name, "states": states, "metrics": metrics}
        )


registry.register("gamespec.transforms", "projectile_to_ocp", ProjectileToOcp)
