"""Parameter sweeps: one problem file, a grid of parameter values, one re-solve per point.

A job carries the validated spec as JSON and the point's parameter values (no file path, so a
cluster without a shared filesystem works); each worker compiles a spec once, cached by its hash,
and re-solves it for every point it gets, with the values named as the file names them
(``evader.speed``, ``pursuers.1.speed``, an OCP parameter ``rho``) and validated as at load (see
:meth:`gamespec.solving.Solver.solve`). Every finished point goes into a :class:`ResultStore`, so
a sweep resumes. Points are keyed by the backend, the hash of the (overridden) spec and the
parameter values, so a folder shared by different sweeps never mixes them up; failed points are
solved again on a rerun.
"""

from __future__ import annotations

import itertools
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from gamespec.errors import SpecError
from gamespec.limits import MAX_SWEEP_POINTS
from gamespec.result import status_ok
from gamespec.studies.executors import Executor, SerialExecutor
from gamespec.studies.rows import StudyMeta, valid_value
from gamespec.studies.runner import StudyRun, run_study
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
    """What one worker needs to solve one point (picklable, self-contained)."""

    spec_json: str
    spec_hash: str
    source: str
    file_hash: str
    backend: str | None
    parameters: tuple[tuple[str, float], ...]


_COMPILED: dict[tuple[str, str | None], Any] = {}
"""This worker's compiled models by (spec hash, backend): compiled once, re-solved per point."""


def _solver(job: SweepJob):
    from gamespec.loader import spec_from_dict
    from gamespec.solving import compile_spec

    key = (job.spec_hash, job.backend)
    if key not in _COMPILED:
        spec = spec_from_dict(json.loads(job.spec_json), source=job.source)
        _COMPILED[key] = compile_spec(spec.with_source(job.source, job.file_hash), job.backend)
    return _COMPILED[key]


def solve_point(job: SweepJob) -> dict[str, Any]:
    """Solve one point with this worker's compiled model; the row that the store keeps."""
    result = _solver(job).solve(parameters=dict(job.parameters))
    return {**dict(job.parameters), **result.summary(), "metrics": result.metrics}


def _solved(row: Any, names: list[str]) -> bool:
    """Whether a stored point is a valid sweep row (:mod:`gamespec.studies.rows`) that solved."""
    try:
        valid_value(row, StudyMeta(type="sweep", parameters=names))
    except ValueError:
        return False
    return status_ok(row["status"])


def sweep(
    path: str | Path,
    ranges: list[tuple[str, list[float]]],
    *,
    out: str | Path,
    overrides: tuple[str, ...] = (),
    backend: str | None = None,
    executor: Executor | None = None,
    show_progress: bool = True,
) -> StudyRun:
    """Solve ``path`` on the Cartesian product of ``ranges``; the run's values in grid order."""
    from gamespec.loader import load, with_values
    from gamespec.solving import backend_name
    from gamespec.specs.hashing import spec_hash

    total = math.prod(len(values) for _, values in ranges)
    if total > MAX_SWEEP_POINTS:
        raise SpecError(f"{total} grid points exceed the limit of {MAX_SWEEP_POINTS}", source="--param")
    spec = load(path, overrides)
    with_values(spec, {name: values[0] for name, values in ranges})
    digest = spec_hash(spec)
    spec_json = json.dumps(spec.model_dump(mode="json"))
    problem = f"{backend_name(spec, backend)}/{digest}"
    names = [name for name, _ in ranges]
    points = {}
    for values in itertools.product(*(vals for _, vals in ranges)):
        params = tuple(zip(names, values, strict=True))
        key = problem + ":" + ",".join(f"{n}={v:.12g}" for n, v in params)
        points[key] = SweepJob(spec_json, digest, str(path), spec.file_hash, backend, params)
    store = ResultStore(out)
    store.set_meta("study", {"type": "sweep", "problem": spec.name, "parameters": names})
    return run_study(
        points,
        solve_point,
        store,
        executor=executor or SerialExecutor(),
        description=f"sweep {Path(path).stem}",
        show_progress=show_progress,
        accept=lambda row: _solved(row, names),
        spec_hash=digest,
    )
