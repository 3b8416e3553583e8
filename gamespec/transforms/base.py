"""Spec → spec reductions after cvxpy's ``Reduction``: ``accepts``, ``apply``, ``invert``.

A transform maps a spec of ``source_kind`` to one of ``target_kind`` and remembers what it needs
to map a Result of the new spec back to the names the user wrote. Transforms are registered in the
``gamespec.transforms`` entry-point group; :func:`chain_to` finds the chain that turns a spec into a
kind a backend takes.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections import deque
from typing import Any, ClassVar

from gamespec import registry
from gamespec.result import Result
from gamespec.specs.base import SpecBase


class Transform(ABC):
    """One reduction step."""

    source_kind: ClassVar[str]
    target_kind: ClassVar[str]

    def accepts(self, spec: SpecBase) -> bool:
        """Whether this transform applies to ``spec``."""
        return spec.kind == self.source_kind

    @abstractmethod
    def apply(self, spec: SpecBase) -> tuple[SpecBase, Any]:
        """Return the new spec and the data :meth:`invert` needs."""

    def invert(self, result: Result, spec: SpecBase, inverse_data: Any) -> Result:
        """Map a Result of the transformed spec back to the original ``spec`` (default: relabel)."""
        return result.model_copy(update={"kind": spec.kind, "problem": spec.name})


def _transforms() -> list[Transform]:
    return [registry.load("gamespec.transforms", n)() for n in registry.names("gamespec.transforms")]


def chain_to(spec: SpecBase, kinds: frozenset[str]) -> list[Transform] | None:
    """The shortest chain of transforms taking ``spec`` to one of ``kinds`` (``[]`` if it is one)."""
    if spec.kind in kinds:
        return []
    available = _transforms()
    queue: deque[tuple[str, list[Transform]]] = deque([(spec.kind, [])])
    seen = {spec.kind}
    while queue:
        kind, path = queue.popleft()
        for t in available:
            if t.source_kind == kind and t.target_kind not in seen:
                if t.target_kind in kinds:
                    return [*path, t]
                seen.add(t.target_kind)
                queue.append((t.target_kind, [*path, t]))
    return None
