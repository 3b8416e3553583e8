"""The solving chain: spec → (transforms) → backend model → Result (DESIGN.md, stages 2–4).

:func:`compile_spec` picks the backend, finds the transforms that take the spec to a kind the
backend solves, compiles once, and returns a :class:`Solver` that re-solves with new parameter
values and warm starts. :func:`solve` is the one-shot form.
"""

from __future__ import annotations

import datetime as _dt
import time
from dataclasses import dataclass
from functools import cache
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

from gamespec import registry
from gamespec.backend import Backend, CompiledModel, Inputs
from gamespec.errors import BackendError, UnsupportedFeature
from gamespec.loader import load, spec_hash
from gamespec.result import Provenance, Result
from gamespec.specs.base import SpecBase
from gamespec.transforms.base import Transform, chain_to


def get_backend(name: str) -> Backend:
    """An instance of the installed, available backend ``name``; BackendError with the reason else."""
    cls = registry.backend_class(name)
    availability = cls.available()
    if not availability.ok:
        raise BackendError(f"backend {name!r} is not available: {availability.reason}")
    return cls()


def backend_name(spec: SpecBase, backend: str | None = None) -> str:
    """The backend to use: the explicit one, the file's ``solver.backend``, or the kind's default."""
    name = backend or spec.solver.backend or spec.default_backend
    if not name:
        raise BackendError(f"no backend given and kind {spec.kind!r} has no default")
    return name


@cache
def _core_versions() -> dict[str, str]:
    found = {}
    for dist in ("gamespec", "numpy", "scipy", "sympy", "pydantic"):
        try:
            found[dist] = version(dist)
        except PackageNotFoundError:
            continue
    return found


def _versions(backend: Backend) -> dict[str, str]:
    return _core_versions() | {
        f"backend:{backend.name}": registry.distribution("gamespec.backends", backend.name)
    }


@dataclass
class Solver:
    """A spec compiled for one backend; call :meth:`solve` as often as needed."""

    spec: SpecBase
    backend: Backend
    transforms: list[tuple[Transform, SpecBase, Any]]
    compiled: CompiledModel
    build_time_s: float

    @property
    def target_spec(self) -> SpecBase:
        """The spec the backend actually solves (after transforms)."""
        return self.transforms[-1][1] if self.transforms else self.spec

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        """Solve (again) with optional new parameter values, an optional guess Result and new grid
        input values (see :meth:`CompiledModel.solve`)."""
        result = self.compiled.solve(parameters=parameters, guess=guess, inputs=inputs)
        for transform, _new, inverse in reversed(self.transforms):
            original = self._source_spec_of(transform)
            result = transform.invert(result, original, inverse)
        provenance = Provenance(
            spec_hash=spec_hash(self.spec),
            source=self.spec.source,
            file_hash=self.spec.file_hash,
            versions=_versions(self.backend),
            created=_dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        )
        return result.model_copy(
            update={
                "backend": self.backend.name,
                "problem": self.spec.name,
                "kind": self.spec.kind,
                "build_time_s": self.build_time_s,
                "provenance": provenance,
            }
        )

    def _source_spec_of(self, transform: Transform) -> SpecBase:
        specs = [self.spec, *(s for _, s, _ in self.transforms)]
        index = [t for t, _, _ in self.transforms].index(transform)
        return specs[index]


def compile_spec(
    spec: SpecBase | str | Path,
    backend: str | None = None,
    options: dict[str, Any] | None = None,
) -> Solver:
    """Load (if a path), pick the backend, apply the transforms it needs, and build its model once."""
    if not isinstance(spec, SpecBase):
        spec = load(spec)
    name = backend_name(spec, backend)
    instance = get_backend(name)
    chain = chain_to(spec, instance.kinds)
    if chain is None:
        raise UnsupportedFeature(f"backend {name!r} does not solve kind {spec.kind!r}")
    start = time.perf_counter()
    applied: list[tuple[Transform, SpecBase, Any]] = []
    current = spec
    for transform in chain:
        new, inverse = transform.apply(current)
        applied.append((transform, new, inverse))
        current = new
    compiled = instance.compile(current, instance.options(current, options))
    build = time.perf_counter() - start
    return Solver(spec, instance, applied, compiled, build)


def solve(
    spec: SpecBase | str | Path,
    backend: str | None = None,
    *,
    parameters: dict[str, float] | None = None,
    guess: Result | None = None,
    options: dict[str, Any] | None = None,
) -> Result:
    """Solve a spec (or problem file) once on ``backend`` and return its Result."""
    return compile_spec(spec, backend, options).solve(parameters=parameters, guess=guess)
