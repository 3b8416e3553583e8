"""Parameter sweeps: one problem file, a grid of parameter values, one re-solve per point.

Each process compiles the spec once and re-solves it with new parameter values, named as the file
names them (``evader.speed``, ``pursuers.1.speed``, an OCP parameter ``rho``) and validated as at
load (see :meth:`gamespec.solving.Solver.solve`); every finished point goes into a
:class:`ResultStore`, so a sweep resumes.
Points are keyed by the backend, the hash of the (overridden) spec and the parameter values, so a
folder shared by different sweeps never mixes them up; failed points are solved again on a rerun.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from gamespec.errors import SpecError
from gamespec.limits import MAX_SWEEP_POINTS
from gamespec.studies.executors import executor
from gamespec.studies.runner import run_study
from gamespec.studies.store import ResultStore


def parse_range(text: str) -> tuple[str, list[float]]:
    """``name=a:b:n`` (n values from a to b) or ``name=v1,v2,...`` → (name, values)."""
    name, sep, spec = text.partition("=")
    if not sep or not name.strip() or not spec.strip():
        raise SpecError(f"expected name=a:b:n or name=v1,v2,..., got {text!r}", source="--param")
    try:
        if ":" in spec:
            a, b, n = spec.split(":")
            count = int(n)
            if count < 1:
                raise ValueError
            if count > MAX_SWEEP_POINTS:
                raise SpecError(
                    f"{count} values in {text!r} exceed the limit of {MAX_SWEEP_POINTS} points",
                    source="--param",
                )
            return name.strip(), [float(v) for v in np.linspace(float(a), float(b), count)]
        return name.strip(), [float(v) for v in spec.split(",")]
    except ValueError:
        raise SpecError(f"cannot read the values in {text!r}", source="--param") from None


@dataclass(frozen=True)
class SweepJob:
    """What one worker needs to solve one point (picklable)."""

    path: str
    overrides: tuple[str, ...]
    backend: str | None
    parameters: tuple[tuple[str, float], ...]


@cache
def _solver(path: str, overrides: tuple[str, ...], backend: str | None):
    from gamespec.loader import load
    from gamespec.solving import compile_spec

    return compile_spec(load(path, overrides), backend)


def solve_point(job: SweepJob) -> dict[str, Any]:
    """Solve one point with the process's compiled model; the row that the store keeps."""
    result = _solver(job.path, job.overrides, job.backend).solve(parameters=dict(job.parameters))
    return {**dict(job.parameters), **result.summary(), "metrics": result.metrics}


def sweep(
    path: str | Path,
    ranges: list[tuple[str, list[float]]],
    *,
    out: str | Path,
    overrides: tuple[str, ...] = (),
    backend: str | None = None,
    workers: int = 1,
    show_progress: bool = True,
) -> list[dict[str, Any]]:
    """Solve ``path`` on the Cartesian product of ``ranges``; rows in grid order."""
    from gamespec.loader import load, spec_hash, with_values
    from gamespec.solving import backend_name

    total = math.prod(len(values) for _, values in ranges)
    if total > MAX_SWEEP_POINTS:
        raise SpecError(f"{total} grid points exceed the limit of {MAX_SWEEP_POINTS}", source="--param")
    spec = load(path, overrides)
    with_values(spec, {name: values[0] for name, values in ranges})
    problem = f"{backend_name(spec, backend)}/{spec_hash(spec)}"
    names = [name for name, _ in ranges]
    points = {}
    for values in itertools.product(*(vals for _, vals in ranges)):
        params = tuple(zip(names, values, strict=True))
        key = problem + ":" + ",".join(f"{n}={v:.12g}" for n, v in params)
        points[key] = SweepJob(str(path), tuple(overrides), backend, params)
    rows = run_study(
        points,
        solve_point,
        ResultStore(Path(out) / "points"),
        executor=executor(workers),
        description=f"sweep {Path(path).stem}",
        show_progress=show_progress,
        accept=lambda row: row["status"] in ("optimal", "feasible"),
    )
    return list(rows.values())
