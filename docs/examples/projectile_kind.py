"""A new problem kind: a projectile fired at ``speed`` and ``angle`` (degrees) under ``gravity``.

A kind is a pydantic model derived from :class:`gamespec.specs.base.SpecBase` whose ``kind`` is a
literal, declared as one :class:`gamespec.registry.Kind` (the model, its default backend, and, when
it has them, its plotter, summary and metrics schema) in the ``gamespec.kinds`` group; files with
``kind: projectile`` load into it.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from gamespec import registry
from gamespec.registry import Kind
from gamespec.specs.base import SpecBase


class ProjectileSpec(SpecBase):
    """A projectile from the origin over flat ground (no drag)."""

    kind: Literal["projectile"] = "projectile"
    speed: float = Field(gt=0, description="Launch speed.")
    angle: float = Field(gt=0, lt=90, description="Launch angle above the ground, degrees.")
    gravity: float = Field(9.81, gt=0, description="Gravitational acceleration.")


registry.register("gamespec.kinds", "projectile", Kind(ProjectileSpec, default_backend="ballistic"))
