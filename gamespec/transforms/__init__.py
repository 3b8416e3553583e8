"""Spec → spec transforms (cvxpy-style reductions); see :mod:`gamespec.transforms.base`."""

from gamespec.transforms.base import Transform, chain_to

__all__ = ["Transform", "chain_to"]
