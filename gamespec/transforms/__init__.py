"""Spec → spec transforms (cvxpy-style reductions); see :mod:`gamespec.transforms.base`."""

from gamespec.transforms.base import Stage, Transform, lowering_path, requested_steps

__all__ = ["Stage", "Transform", "lowering_path", "requested_steps"]
