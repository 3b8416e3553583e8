"""Plots of ``optimal_control`` Results: states, controls and, for declared planar pairs, the path;
the boundaries between the phases of a ``multiphase_optimal_control`` Result are marked.

Plotters read Results only (never solver objects); each kind names its own (its
:class:`~gamespec.registry.Kind`'s ``plot``) and each transform its figures (its ``plot``), and
:func:`plot_result` draws the kind's then those of the transforms the Result went through. The
planar pairs, units and path constraints come from ``metrics["plot"]`` (the file's ``plot``
section, :mod:`gamespec.specs.plot`); a plane is drawn only when the file declares one.
"""

from __future__ import annotations

from pathlib import Path

from gamespec.rcs.circles import circles
from gamespec.result import Result

LEGEND_RIGHT = {"loc": "upper left", "bbox_to_anchor": (1.02, 1.0), "borderaxespad": 0.0, "fontsize": "small"}
"""Legend placement outside the axes, to their right, so that it never covers the data."""


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


def plot_trajectories(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """States and controls against time, and the path of each declared planar pair."""
    plt = _pyplot()
    output_dir.mkdir(parents=True, exist_ok=True)
    hint = result.metrics.get("plot", {})
    units = hint.get("units", {})
    rows = 2 if result.controls else 1
    fig, axes = plt.subplots(rows, 1, figsize=(8, 3.2 * rows), sharex=True, squeeze=False)
    for name, values in result.states.items():
        axes[0, 0].plot(result.time, values, label=_label(name, units))
    axes[0, 0].set_ylabel("states")
    axes[0, 0].legend(**LEGEND_RIGHT)
    if result.controls:
        tc = result.control_time if result.control_time is not None else result.time
        for name, values in result.controls.items():
            axes[1, 0].plot(tc, values, ".-", label=_label(name, units), markersize=3)
        axes[1, 0].set_ylabel("controls")
        axes[1, 0].legend(**LEGEND_RIGHT)
    _mark_phases(result, axes[:, 0])
    axes[-1, 0].set_xlabel(_label("t", units))
    title = headline(result)
    if result.t_final is not None and result.objective is not None:
        title += f", t_f = {result.t_final:.6g}"
    fig.suptitle(title)
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
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def plot_result(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """The figures of the Result's kind, then those of each transform its chain applied, written
    into ``output_dir`` (:meth:`gamespec.result.Result.plot`, which notebooks call too)."""
    return result.plot(output_dir, animate=animate).paths
