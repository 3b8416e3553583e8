"""Plots of ``optimal_control`` Results: states, controls and, for declared planar pairs, the path;
the boundaries between the phases of a ``multiphase_optimal_control`` Result are marked.

Plotters read Results only (never solver objects); each kind names its own (its
:class:`~gamespec.registry.Kind`'s ``plot``) and each transform its figures (its ``plot``), and
:func:`plot_result` draws the kind's then those of the transforms the Result went through. The
planar pairs, units and path constraints come from ``metrics["plot"]`` (the file's ``plot``
section, :mod:`gamespec.specs.plot`); a plane is drawn only when the file declares one.

What a figure shows is what was solved, and nothing a reader could mistake for more:

- controls are drawn as the transcription holds them (:mod:`gamespec.ocp.control_signal`: the
  polynomial of each mesh interval, a jump between intervals drawn as a vertical step), with their
  control points as dots;
- a signal whose variation is below :data:`FLAT_TOLERANCE` (what the solver's tolerances leave) is
  drawn flat at its mean, with "constant" in the legend, and no axis has an offset or a zoom
  (matplotlib's "1e-7+1" drew a constant u = 1 as a sawtooth);
- the ``angles`` of the file's ``plot`` section are drawn unwrapped (:func:`numpy.unwrap`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gamespec.ocp.control_signal import step_edges, transcribed_signal
from gamespec.rcs.circles import circles
from gamespec.result import Result

LEGEND_RIGHT = {"loc": "upper left", "bbox_to_anchor": (1.02, 1.0), "borderaxespad": 0.0, "fontsize": "small"}
"""Legend placement outside the axes, to their right, so that it never covers the data."""

FLAT_TOLERANCE = 1e-6
"""A signal whose spread (max − min) is at most this times ``max(1, max |value|)`` is drawn flat:
variation at the level of an NLP solver's tolerances (IPOPT's ``tol`` 1e-8 on scaled data, bounds
relaxed by 1e-8 relative) is no feature of the solution."""

SAMPLES_PER_INTERVAL = 8
"""Points drawn on each mesh interval of a control (its polynomial between its control points)."""


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def headline(result: Result) -> str:
    """``problem — backend, status, <headline number>``: the first line of every figure's title."""
    number = ""
    if result.objective is not None:
        number = f", J = {result.objective:.6g}"
    elif result.t_final is not None:
        number = f", t_f = {result.t_final:.6g}"
    return f"{result.problem} — {result.backend}, {result.status.value}{number}"


def _label(name: str, units: dict[str, str]) -> str:
    return f"{name} [{units[name]}]" if name in units else name


def is_flat(values: np.ndarray) -> bool:
    """Whether ``values`` vary by no more than :data:`FLAT_TOLERANCE` (relative, see there)."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    if finite.size < 2:
        return False
    return float(np.ptp(finite)) <= FLAT_TOLERANCE * max(1.0, float(np.max(np.abs(finite))))


def as_drawn(values: np.ndarray, name: str, angles: list[str]) -> tuple[np.ndarray, str]:
    """``values`` as a figure draws them and the suffix of their legend entry: unwrapped when
    ``name`` is one of the ``angles``; flat at the mean, "(constant = v)", when :func:`is_flat`."""
    values = np.asarray(values, dtype=float)
    if name in angles and values.size > 1 and np.all(np.isfinite(values)):
        values = np.unwrap(values)
    if is_flat(values):
        step = FLAT_TOLERANCE * max(1.0, float(np.nanmax(np.abs(values))))
        level = float(np.round(np.nanmean(values) / step) * step) + 0.0
        return np.full_like(values, level), f" (constant = {level:.6g})"
    return values, ""


def no_offsets(fig) -> None:
    """No axis of ``fig`` shows an offset or a multiplier ("1e-7+1", "1e-14"): ticks read as the
    values."""
    from matplotlib.ticker import ScalarFormatter

    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            formatter = axis.get_major_formatter()
            if isinstance(formatter, ScalarFormatter):
                formatter.set_useOffset(False)
                formatter.set_scientific(False)


def _controls_drawn(result: Result, angles: list[str]) -> tuple[dict[str, tuple], np.ndarray]:
    """Per control: (dense times, dense values, legend suffix) of its polynomial on each mesh
    interval (:func:`~gamespec.ocp.control_signal.transcribed_signal`), and its control points'
    values as drawn; the time grid of those points."""
    tc = np.asarray(result.control_time if result.control_time is not None else result.time, dtype=float)
    drawn = {name: as_drawn(values, name, angles) for name, values in result.controls.items()}
    shown = result.model_copy(update={"controls": {n: v for n, (v, _) in drawn.items()}})
    names = list(result.controls)
    mesh = result.arrays.get("control_mesh")
    t0, tf = float(result.time[0]), float(result.time[-1])
    intervals = len(mesh) - 1 if mesh is not None else max(len(tc) - 1, 1)
    inside = tc[(tc > t0) & (tc < tf)]
    edges = np.union1d(step_edges(mesh, t0, tf, SAMPLES_PER_INTERVAL * intervals), inside)
    stages = transcribed_signal(shown, names).on_steps(edges)
    times = np.stack([edges[:-1], 0.5 * (edges[:-1] + edges[1:]), edges[1:]], axis=1).ravel()
    out = {}
    for row, name in enumerate(names):
        points, suffix = drawn[name]
        dense = np.full(times.shape, points[0]) if suffix else stages[row].ravel()
        out[name] = (times, dense, suffix, points)
    return out, tc


def plot_trajectories(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """States and controls against time (as the module doc says they are drawn), and the path of
    each declared planar pair."""
    plt = _pyplot()
    output_dir.mkdir(parents=True, exist_ok=True)
    hint = result.metrics.get("plot", {})
    units = hint.get("units", {})
    angles = list(hint.get("angles", []))
    rows = 2 if result.controls else 1
    fig, axes = plt.subplots(rows, 1, figsize=(8, 3.2 * rows), sharex=True, squeeze=False)
    for name, values in result.states.items():
        shown, suffix = as_drawn(values, name, angles)
        axes[0, 0].plot(result.time, shown, label=_label(name, units) + suffix)
    axes[0, 0].set_ylabel("states")
    axes[0, 0].set_title("states", fontsize="medium")
    axes[0, 0].legend(**LEGEND_RIGHT)
    if result.controls:
        controls, tc = _controls_drawn(result, angles)
        for i, (name, (times, values, suffix, points)) in enumerate(controls.items()):
            colour = f"C{i}"
            axes[1, 0].plot(times, values, "-", color=colour, label=_label(name, units) + suffix)
            axes[1, 0].plot(tc, points, ".", color=colour, markersize=4)
        axes[1, 0].plot([], [], ".", color="0.3", label="control points")
        axes[1, 0].set_ylabel("controls")
        axes[1, 0].set_title(
            "controls (per mesh interval, as the transcription holds them)", fontsize="medium"
        )
        axes[1, 0].legend(**LEGEND_RIGHT)
    _mark_phases(result, axes[:, 0])
    axes[-1, 0].set_xlabel(_label("t", units))
    title = headline(result)
    if result.t_final is not None and result.objective is not None:
        title += f", t_f = {result.t_final:.6g}"
    fig.suptitle(title)
    no_offsets(fig)
    fig.tight_layout()
    paths = [output_dir / f"{result.problem}_time.png"]
    fig.savefig(paths[0], dpi=120, bbox_inches="tight")
    plt.close(fig)
    pairs = [tuple(p) for p in hint.get("planar", [])]
    if pairs:
        paths.append(plot_plane(result, pairs, output_dir / f"{result.problem}_path.png"))
    return paths


def _mark_phases(result: Result, axes) -> None:
    """A dotted vertical line at each boundary between phases (``metrics["phases"]`` of a
    multi-phase Result), named by the phase that starts there."""
    for phase in result.metrics.get("phases", [])[1:]:
        for ax in axes:
            ax.axvline(phase["start"], color="0.4", ls=":", lw=1)
        axes[0].annotate(
            phase["name"],
            (phase["start"], 1.0),
            xycoords=("data", "axes fraction"),
            fontsize="small",
            xytext=(3, -10),
            textcoords="offset points",
        )


def plot_plane(result: Result, pairs: list[tuple[str, str]], path: Path) -> Path:
    """The path of each planar pair (start ``o``, end ``s``) with the circular path constraints over
    it: obstacles as grey disks, keep-in circles as dashed outlines (:mod:`gamespec.rcs.circles`)."""
    plt = _pyplot()
    hint = result.metrics.get("plot", {})
    units = hint.get("units", {})
    names = [*result.states, *result.controls, *(k.split("/", 1)[1] for k in result.arrays if "/" in k)]
    fig, ax = plt.subplots(figsize=(6.5, 5))
    for i, (xs, ys) in enumerate(pairs):
        colour = f"C{i}"
        x, y = result.states[xs], result.states[ys]
        ax.plot(x, y, "-", color=colour, label=f"({xs}, {ys})")
        ax.plot(x[0], y[0], "o", color=colour, label=f"start of ({xs}, {ys})")
        ax.plot(x[-1], y[-1], "s", color=colour, label=f"end of ({xs}, {ys})")
        for circle in circles(hint.get("path_constraints", []), (xs, ys), names, result.parameters):
            if circle.keep_out:
                patch = plt.Circle(circle.center, circle.radius, color="0.6", alpha=0.5, label=circle.text)
            else:
                patch = plt.Circle(
                    circle.center, circle.radius, fill=False, ls="--", color="0.3", label=circle.text
                )
            ax.add_patch(patch)
    ax.set_xlabel(", ".join(_label(p[0], units) for p in pairs))
    ax.set_ylabel(", ".join(_label(p[1], units) for p in pairs))
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.grid(alpha=0.3)
    ax.set_title(headline(result), fontsize="medium")
    ax.legend(**LEGEND_RIGHT)
    no_offsets(fig)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def plot_result(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """The figures of the Result's kind, then those of each transform its chain applied, written
    into ``output_dir`` (:meth:`gamespec.result.Result.plot`, which notebooks call too)."""
    return result.plot(output_dir, animate=animate).paths
