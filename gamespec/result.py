"""One result type for every backend and every kind (DESIGN.md, stage 4).

A :class:`Result` holds the status, the objective, trajectories on a time grid, backend-independent
checks, solver statistics, timings and provenance. It is saved as ``result.json`` plus
``arrays.npz`` and read back without any solver installed. Plots and reports read Results only.

In a notebook a Result shows itself (:meth:`Result._repr_html_`: status, the kind's summary rows, the
scalars and the failed checks) and draws its figures (:meth:`Result.plot`) through the plotters its
kind and transforms register, the ones ``gamespec plot`` uses.
"""

from __future__ import annotations

import base64
import html
import json
import math
import os
import stat
import tempfile
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_serializer, field_validator

from gamespec import limits, registry
from gamespec.errors import BackendError, GamespecError, SpecError

ArrayDict = dict[str, np.ndarray]


class Status(StrEnum):
    """Backend-independent outcome of a solve (each backend maps its native statuses here).

    One meaning in every kind (the table in README.md, "Statuses", and ``docs/statuses.md``);
    :attr:`ok` statuses exit 0, the others exit 1.
    """

    OPTIMAL = "optimal"
    """The solver proved (local) optimality; a closed form is optimal where it is the optimum."""
    FEASIBLE = "feasible"
    """A usable solution with no optimality claim: acceptable-level stops, suboptimal strategies,
    optima that failed a check; the message says why."""
    SIMULATED = "simulated"
    """A simulation ran to its end: every evader captured, or the horizon reached (escapes are a
    result, listed in the metrics); nothing is optimized, so nothing is claimed optimal."""
    INFEASIBLE = "infeasible"
    """No solution exists: the solver proved it (a convex solver's certificate of infeasibility)."""
    LOCALLY_INFEASIBLE = "locally_infeasible"
    """A local NLP solver (IPOPT, ripopt) converged to a point that minimizes the constraint
    violation without reaching zero: no feasible point *near where it looked*. A solution may still
    exist; try another initial guess, finer grid or bounds before concluding there is none."""
    UNBOUNDED = "unbounded"
    """The objective improves without bound."""
    ITERATION_LIMIT = "iteration_limit"
    """The solver, or a game's iteration, stopped at its iteration limit before converging."""
    NOT_CONVERGED = "not_converged"
    """An iteration stopped before its limit because it cannot converge: best responses that cycle
    or diverge (:mod:`gamespec.best_response`); the message says which."""
    TIME_LIMIT = "time_limit"
    """The solver stopped at its wall-clock or CPU-time limit (never a simulation's horizon)."""
    NUMERICAL_ERROR = "numerical_error"
    """The solver failed numerically (restoration failure, NaN, an ill-conditioned step)."""
    ERROR = "error"
    """Anything else that left no solution; the message says what."""

    @property
    def ok(self) -> bool:
        """True for statuses that carry a usable solution."""
        return self in OK_STATUSES


OK_STATUSES = frozenset({Status.OPTIMAL, Status.FEASIBLE, Status.SIMULATED})
"""Statuses that carry a usable solution (exit code 0)."""


def status_ok(value: str) -> bool:
    """Whether a status written as text (a table row, a JSON Result) carries a usable solution."""
    return value in {s.value for s in OK_STATUSES}


@dataclass(frozen=True)
class FailedCheck:
    """A check with a tolerance that did not pass: its value (None where it could not be computed)
    and its tolerance (None where the Result gives none)."""

    name: str
    value: float | None
    tolerance: float | None

    def __str__(self) -> str:
        value = "not computable" if _missing(self.value) else f"{self.value:.3g}"
        bound = "" if self.tolerance is None else f" > tolerance {self.tolerance:.3g}"
        return f"{self.name} = {value}{bound}"


def _missing(value: Any) -> bool:
    return value is None or (isinstance(value, float) and not math.isfinite(value))


@dataclass(frozen=True)
class Figures:
    """The figures :meth:`Result.plot` drew: the files it wrote, or, when it drew them in a
    temporary folder, each figure's name and bytes (``drawn``); shown inline by a notebook."""

    paths: list[Path]
    drawn: tuple[tuple[str, bytes], ...] = ()

    @property
    def images(self) -> list[tuple[str, bytes]]:
        """Each figure's file name and bytes (read from :attr:`paths` when they were written)."""
        return list(self.drawn) or [(path.name, path.read_bytes()) for path in self.paths]

    def _repr_html_(self) -> str:
        """Each figure as an ``<img>`` with its bytes inline (PNG or GIF), captioned by its name."""
        parts = []
        for name, data in self.images:
            mime = "image/gif" if name.endswith(".gif") else "image/png"
            source = f"data:{mime};base64,{base64.b64encode(data).decode()}"
            caption = html.escape(name)
            parts.append(
                f'<figure><img src="{source}" alt="{caption}"><figcaption>{caption}</figcaption></figure>'
            )
        return "\n".join(parts)


def _html_value(value: Any) -> str:
    text = f"{value:.6g}" if isinstance(value, float) else str(value)
    return html.escape(text)


class Provenance(BaseModel):
    """Where a Result came from: the spec's hash (after overrides), its file and the file's hash,
    package versions, when."""

    model_config = ConfigDict(extra="allow")

    spec_hash: str = ""
    source: str = ""
    file_hash: str = ""
    versions: dict[str, str] = Field(default_factory=dict)
    created: str = ""
    transforms: list[str] = Field(default_factory=list)
    """The transforms the chain applied, in order (requested, then lowering)."""


class Result(BaseModel):
    """The outcome of solving one spec on one backend.

    ``time`` is the grid of ``states``/``costates`` (and of ``controls``, which may have their own
    grid ``control_time`` when a transcription puts them elsewhere). ``checks`` hold quantities
    recomputed independently of the solver (``max_constraint_violation``, ``max_defect``,
    ``hamiltonian_max_abs`` ...). ``metrics`` hold kind-specific results (capture times, terminal
    covariance, ...) and must be JSON-able. ``arrays`` hold any other named arrays.
    """

    model_config = ConfigDict(arbitrary_types_allowed=True, extra="forbid")

    problem: str = ""
    kind: str = ""
    backend: str = ""
    status: Status
    message: str = ""
    objective: float | None = None
    t_final: float | None = None
    solve_time_s: float = 0.0
    """Wall-clock seconds the caller waited for the solve (set by the chain: the backend's solve,
    the checks, the inverse maps and any multi-start)."""
    build_time_s: float = 0.0
    iterations: int | None = None
    time: np.ndarray | None = None
    control_time: np.ndarray | None = None
    states: ArrayDict = Field(default_factory=dict)
    controls: ArrayDict = Field(default_factory=dict)
    costates: ArrayDict = Field(default_factory=dict)
    arrays: ArrayDict = Field(default_factory=dict)
    parameters: dict[str, float] = Field(default_factory=dict)
    checks: dict[str, float | None] = Field(default_factory=dict)
    metrics: dict[str, Any] = Field(default_factory=dict)
    solver_stats: dict[str, Any] = Field(default_factory=dict)
    provenance: Provenance = Field(default_factory=Provenance)

    @field_validator("time", "control_time", mode="before")
    @classmethod
    def _as_array(cls, v: Any) -> np.ndarray | None:
        return None if v is None else np.asarray(v, dtype=float)

    @field_validator("states", "controls", "costates", "arrays", mode="before")
    @classmethod
    def _as_arrays(cls, v: Any) -> ArrayDict:
        if not isinstance(v, dict | None):
            raise ValueError("expected a mapping of names to arrays")
        return {k: np.asarray(a) for k, a in (v or {}).items()}

    @field_serializer("time", "control_time")
    def _ser_array(self, v: np.ndarray | None) -> list[Any] | None:
        return None if v is None else v.tolist()

    @field_serializer("states", "controls", "costates", "arrays")
    def _ser_arrays(self, v: ArrayDict) -> dict[str, list[Any]]:
        return {k: a.tolist() for k, a in v.items()}

    @property
    def ok(self) -> bool:
        """True when the status carries a usable solution."""
        return self.status.ok

    def failed_checks(self) -> list[FailedCheck]:
        """The checks with a verdict or a tolerance that did not pass (the status policy's input,
        see :func:`gamespec.solving.status_policy`): a verdict ``metrics["checks_passed"][name]``
        that is False; a check whose value ``checks[name]`` is NaN or None (not computable); or,
        with no verdict, a value above its tolerance ``metrics["check_tolerances"][name]``."""
        verdicts = self.metrics.get("checks_passed", {})
        tolerances = self.metrics.get("check_tolerances", {})
        failed = []
        for name in sorted(set(verdicts) | set(tolerances)):
            value, tolerance = self.checks.get(name), tolerances.get(name)
            if name in verdicts:
                passed = bool(verdicts[name]) and not (name in self.checks and _missing(value))
            else:
                passed = not _missing(value) and value <= tolerance
            if not passed:
                failed.append(FailedCheck(name, value, tolerance))
        return failed

    def summary(self) -> dict[str, Any]:
        """The scalar fields: what ``--json`` always shows and what tables are made of."""
        return {
            "problem": self.problem,
            "kind": self.kind,
            "backend": self.backend,
            "status": self.status.value,
            "message": self.message,
            "objective": self.objective,
            "t_final": self.t_final,
            "solve_time_s": self.solve_time_s,
            "build_time_s": self.build_time_s,
            "iterations": self.iterations,
            **{k: v for k, v in self.checks.items()},
        }

    def summary_rows(self) -> list[tuple[str, object]]:
        """The rows of the kind's summary (its :class:`~gamespec.registry.Kind`'s ``summary``; none
        when the kind names none or is not installed), then those of each transform the chain applied
        that names one (:func:`~gamespec.registry.transform_parts`)."""
        own = registry.kind_part(self.kind, "summary")
        summaries = [own, *registry.transform_parts(self.provenance.transforms, "summary")]
        return [row for summary in summaries if summary is not None for row in summary(self)]

    def _repr_html_(self) -> str:
        """The Result in a notebook: problem, kind, backend and status over its message, a table of
        the kind's summary rows (:meth:`summary_rows`), the scalars of :meth:`summary` and the other
        scalar metrics, then one row per failed check (:meth:`failed_checks`)."""
        shown = {"problem", "kind", "backend", "status", "message"}
        scalars = {k: v for k, v in self.summary().items() if k not in shown and v not in (None, "")}
        scalars |= {
            k: v for k, v in self.metrics.items() if isinstance(v, int | float | str) and k not in scalars
        }
        rows = [
            *self.summary_rows(),
            *scalars.items(),
            *(("failed check", str(f)) for f in self.failed_checks()),
        ]
        cells = "".join(
            f'<tr><th style="text-align:left">{html.escape(str(k))}</th><td>{_html_value(v)}</td></tr>'
            for k, v in rows
        )
        head = (
            f"<strong>{html.escape(self.problem)}</strong> ({html.escape(self.kind)}) on "
            f"{html.escape(self.backend)}: <strong>{html.escape(self.status.value)}</strong>"
        )
        message = f"<p>{html.escape(self.message)}</p>" if self.message else ""
        return f'<div class="gamespec-result"><p>{head}</p>{message}<table>{cells}</table></div>'

    def plot(self, directory: str | Path | None = None, *, animate: bool = False) -> Figures:
        """Draw the Result's figures into ``directory`` (a temporary folder, removed once the
        figures are read, when None): those of its kind's plotter (the kind's ``plot``), then those of
        each transform its chain applied (:func:`~gamespec.registry.transform_parts`), with the
        metrics validated by the kind's schema (:func:`gamespec.metrics.validated`), so a plotter
        reads only metrics of the types and shapes that schema promises. ``gamespec plot`` draws
        with this method (:func:`gamespec.plotting.plot_result`). A BackendError when the kind has
        no plotter."""
        if directory is None:
            with tempfile.TemporaryDirectory() as folder:
                return Figures([], tuple(self.plot(folder, animate=animate).images))
        plotter = registry.kind(self.kind).part("plot")
        if plotter is None:
            raise BackendError(f"kind {self.kind!r} has no plotter")
        from gamespec.metrics import validated

        typed = validated(self, self.problem or "<result>")
        out = Path(directory)
        paths = list(plotter(typed, out, animate=animate))
        for plot in registry.transform_parts(self.provenance.transforms, "plot"):
            paths += plot(typed, out)
        return Figures(paths)

    def to_json(self, *, arrays: bool = True, indent: int | None = 2) -> str:
        """JSON text of the Result; with ``arrays=False`` only scalars, checks and metrics."""
        exclude = None if arrays else _ARRAY_FIELDS
        data = self.model_dump(mode="json", exclude=exclude)
        return json.dumps(_finite(data), indent=indent)

    def save(self, directory: str | Path) -> Path:
        """Write ``result.json`` (scalars, metrics) and ``arrays.npz`` (every array) into ``directory``."""
        out = writable_folder(directory)
        (out / "result.json").write_text(self.to_json(arrays=False))
        packed: dict[str, np.ndarray] = {}
        for field in _ARRAY_FIELDS:
            value = getattr(self, field)
            if isinstance(value, np.ndarray):
                packed[field] = value
            elif isinstance(value, dict):
                packed.update({f"{field}/{k}": a for k, a in value.items()})
        np.savez_compressed(out / "arrays.npz", allow_pickle=False, **packed)
        return out

    @classmethod
    def load(cls, path: str | Path) -> Result:
        """Read a Result saved by :meth:`save` (a folder or its ``result.json``), or a ``--json`` dump;
        a SpecError naming the file that cannot be read and why. The folder is untrusted input
        (README, "Security"): only regular files inside it are opened (:func:`open_regular`), within
        the limits of :mod:`gamespec.limits` (:mod:`gamespec.npyfile` for the arrays), and the
        Result must hold together: trajectories with one row per point of their finite time grid,
        and ``metrics`` of the kind's schema (:func:`gamespec.metrics.validated`)."""
        path = Path(path)
        folder = path if path.is_dir() else path.parent
        json_file = path / "result.json" if path.is_dir() else path
        data = _read_json(folder, json_file)
        npz = folder / "arrays.npz"
        saved = json_file.name == "result.json" and (npz.is_symlink() or npz.exists())
        if saved:
            data.update(_read_arrays(folder, npz))
        try:
            result = cls.model_validate(data)
            result._check_readable()
        except ValueError as err:
            source = npz if saved else json_file
            raise SpecError(f"not a readable Result: {_first_line(err)}", source=str(source)) from None
        from gamespec.metrics import validated

        return validated(result, str(json_file))

    def _check_readable(self) -> None:
        """ValueError unless the problem's name is one file-name component (figures are named
        after it), every array holds numbers or text, the time grids are finite vectors
        and every trajectory has one row per point of its grid (``states`` on ``time``,
        ``controls`` on ``control_time`` or ``time``, ``costates`` on ``arrays["costate_time"]``
        or ``time``)."""
        if not self.problem or self.problem.startswith(".") or {"/", "\\", "\0"} & set(self.problem):
            raise ValueError(f"problem {self.problem!r} is not a name figures can be written under")
        for field in ("states", "controls", "costates", "arrays"):
            for name, values in getattr(self, field).items():
                if values.dtype.kind not in "biufcU":
                    raise ValueError(f"{field}.{name} is not an array of numbers or text ({values.dtype})")
        grids = {"time": self.time, "control_time": self.control_time, "costate_time": None}
        if "costate_time" in self.arrays:
            grids["costate_time"] = np.asarray(self.arrays["costate_time"], dtype=float)
        for name, grid in grids.items():
            if grid is not None and (grid.ndim != 1 or not np.all(np.isfinite(grid))):
                raise ValueError(f"{name} is not a finite vector")
        for field, grid in (
            ("states", self.time),
            ("controls", self.control_time if self.control_time is not None else self.time),
            ("costates", grids["costate_time"] if grids["costate_time"] is not None else self.time),
        ):
            for name, values in getattr(self, field).items():
                if grid is not None and (values.ndim == 0 or len(values) != len(grid)):
                    raise ValueError(f"{field}.{name} has {values.shape} values for {len(grid)} time points")


def _first_line(err: BaseException) -> str:
    text = err.strerror if isinstance(err, OSError) and err.strerror else str(err)
    return " ".join(text.split("\n")[0].split()) or type(err).__name__


def open_regular(folder: Path, path: Path, max_bytes: int) -> BinaryIO:
    """``path`` opened for reading when it is a regular file of at most ``max_bytes`` that resolves
    inside ``folder`` (symlinks within it are followed); a SpecError naming it otherwise. A FIFO or
    a device is refused without blocking (it is opened non-blocking and checked before any read)."""
    try:
        inside = path.resolve().is_relative_to(folder.resolve())
    except (OSError, RuntimeError) as err:
        raise SpecError(f"not a readable Result: {_first_line(err)}", source=str(path)) from None
    if not inside:
        raise SpecError(f"not a readable Result: it leads out of {folder}", source=str(path))
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as err:
        raise SpecError(f"not a readable Result: {_first_line(err)}", source=str(path)) from None
    info = os.fstat(fd)
    why = None
    if not stat.S_ISREG(info.st_mode):
        why = "not a regular file (a FIFO, a device, a socket or a folder)"
    elif info.st_size > max_bytes:
        why = f"{info.st_size} bytes, more than the limit of {max_bytes}"
    if why is not None:
        os.close(fd)
        raise SpecError(f"not a readable Result: {why}", source=str(path))
    os.set_blocking(fd, True)
    return os.fdopen(fd, "rb")


def _read_json(folder: Path, json_file: Path) -> dict[str, Any]:
    """The mapping in a Result's JSON file; a SpecError naming it when it is missing or not one."""
    with open_regular(folder, json_file, limits.MAX_RESULT_JSON_BYTES) as handle:
        try:
            data = json.loads(handle.read(limits.MAX_RESULT_JSON_BYTES + 1).decode("utf-8"))
        except (OSError, UnicodeDecodeError, ValueError, RecursionError) as err:
            raise SpecError(f"not a readable Result: {_first_line(err)}", source=str(json_file)) from None
    if not isinstance(data, dict):
        raise SpecError("not a readable Result: the JSON does not hold a mapping", source=str(json_file))
    return data


def _read_arrays(folder: Path, npz: Path) -> dict[str, Any]:
    """The arrays of ``arrays.npz`` as Result fields (``states/x`` → ``states["x"]``); a SpecError
    naming the file when it cannot be read within the limits (:mod:`gamespec.npyfile`)."""
    from gamespec.npyfile import UnreadableArrays, read_npz

    fields: dict[str, Any] = {}
    with open_regular(folder, npz, limits.MAX_RESULT_NPZ_BYTES) as handle:
        try:
            arrays = read_npz(handle)
        except (UnreadableArrays, OSError) as err:
            raise SpecError(f"not a readable Result: {_first_line(err)}", source=str(npz)) from None
    for key, array in arrays.items():
        field, _, name = key.partition("/")
        if field not in _ARRAY_FIELDS:
            raise SpecError(f"not a readable Result: an array {key!r} of no Result field", source=str(npz))
        if name:
            fields.setdefault(field, {})[name] = array
        elif field in ("time", "control_time"):
            fields[field] = array
        else:
            raise SpecError(f"not a readable Result: {key!r} is a field of named arrays", source=str(npz))
    return fields


def writable_folder(directory: str | Path) -> Path:
    """``directory``, created if needed; a GamespecError when it cannot be written to."""
    out = Path(directory)
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".gamespec-write-test"
        probe.touch()
        probe.unlink()
    except OSError as err:
        raise GamespecError(f"{out}: cannot write there ({err.strerror or err})") from None
    return out


_ARRAY_FIELDS = {"time", "control_time", "states", "controls", "costates", "arrays"}


def _finite(value: Any) -> Any:
    """Replace NaN/inf by None so the JSON is standard."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value
