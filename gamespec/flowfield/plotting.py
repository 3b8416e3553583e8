"""Plots of a ``flow_field_game`` Result (registered as that kind's plotter), red the pursuer and
blue the evader as in the thesis:

- ``reachable_sets.png``: both reachable sets at ``T̂`` (the upper level read, or the extremal
  fronts) with the nominal paths and the capture point (Figs. 5.1, 5.4(a));
- ``dispersion.png``: closed-loop Monte Carlo paths of both agents (Figs. 5.3, 5.4(b));
- ``capture_probability.png``: eq. 5.39 per step, open loop, closed loop, and the pursuer's
  feedback against the open-loop evader.

:func:`plot_capture_sweep` draws the capture probability at ``T̂`` against a swept parameter (the
noise level α: Fig. 5.2) from the points of a ``gamespec sweep`` folder (``gamespec plot DIR``) or
from Results' metrics.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes

from gamespec.plotting import LEGEND_RIGHT, headline
from gamespec.result import Result

COLORS = ("tab:red", "tab:blue")
LOOPS = (("open_loop", "o"), ("lower_value", "^"), ("minimax_mixed", "s"), ("gauss_seidel", "v"))
"""Eq. 5.39 in open loop, at the lower value (the pursuer's feedback answers the evader's committed
gains: the thesis' closed loop), at the mixed minimax (a worst-case evader) and at Algorithm 3's
last iterate (:mod:`gamespec.flowfield.concepts`); whichever the file chose is also
``closed_loop``."""


def _level(result: Result) -> str:
    levels = result.metrics["reachability"].get("levels")
    return f"{levels[1]:.3g}" if levels else "0"


def _sets(ax: Axes, result: Result) -> None:
    arrays = result.arrays
    if "phi_final" in arrays:
        level = result.metrics["reachability"]["levels"][1]
        for phi, color in zip(arrays["phi_final"], COLORS, strict=True):
            ax.contour(arrays["grid_x"], arrays["grid_y"], phi.T, levels=[level], colors=color, linewidths=1)
    elif "front_final" in arrays:
        for front, color in zip(arrays["front_final"], COLORS, strict=True):
            closed = np.vstack([front, front[:1]])
            ax.plot(closed[:, 0], closed[:, 1], color=color, lw=1)
    for path, color, name in zip(arrays["nominal_positions"], COLORS, ("pursuer", "evader"), strict=True):
        ax.plot([], [], "-", color=color, lw=1, label=f"{name}'s reachable set")
        ax.plot(path[:, 0], path[:, 1], "--", color=color, label=f"{name} (nominal)")
        ax.plot(*path[0], "o", color=color)
    ax.plot(*result.metrics["capture_point"], "k*", ms=10, label="capture point")
    ax.set(xlabel="x", ylabel="y")
    title = f"reachable sets at T̂ = {result.metrics['capture_time']:.3f}"
    if "phi_final" in arrays:
        level = _level(result)
        title += f"\nlevel φ = {level}: the sets reached from disks of radius {level} about the starts"
    ax.set_title(title, fontsize="medium")


def _dispersion(ax: Axes, result: Result) -> None:
    paths = result.arrays["monte_carlo_closed_loop"]
    for i, color in enumerate(COLORS):
        for sample in paths:
            ax.plot(sample[:, 2 * i], sample[:, 2 * i + 1], color=color, lw=0.3, alpha=0.3)
    for path in result.arrays["nominal_positions"]:
        ax.plot(path[:, 0], path[:, 1], "k--", lw=0.8)
    drawn = len(paths)
    for color, name in zip(COLORS, ("pursuer", "evader"), strict=True):
        ax.plot([], [], color=color, lw=1, label=f"{name}, closed loop ({drawn} sampled paths)")
    ax.plot([], [], "k--", lw=0.8, label="nominal paths")
    ax.set(xlabel="x", ylabel="y")
    ax.set_title("closed-loop trajectory dispersion (Monte Carlo)", fontsize="medium")


def _probability(ax: Axes, result: Result) -> None:
    t = result.time[1:]
    for loop, marker in LOOPS:
        if f"capture_probability_{loop}" in result.arrays:
            label = loop.replace("_", " ")
            ax.plot(t, result.arrays[f"capture_probability_{loop}"], marker + "-", label=label)
    ax.set_xlabel("t")
    ax.set_ylabel("capture probability (eq. 5.39)")
    ax.set_title("capture probability by time step", fontsize="medium")


def plot(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """Write the figures of a flow-field game Result into ``output_dir``; return their paths."""
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    figures = []
    if "nominal_positions" in result.arrays:
        figures += [("reachable_sets.png", _sets), ("capture_probability.png", _probability)]
    if "monte_carlo_closed_loop" in result.arrays:
        figures.append(("dispersion.png", _dispersion))
    written = []
    for name, draw in figures:
        fig, ax = plt.subplots(figsize=(7.5, 4.5))
        draw(ax, result)
        ax.set_title(f"{headline(result)}\n{ax.get_title()}", fontsize="medium")
        ax.legend(**LEGEND_RIGHT)
        if name != "capture_probability.png":
            ax.set_aspect("equal")
        fig.savefig(output_dir / name, dpi=120, bbox_inches="tight")
        plt.close(fig)
        written.append(output_dir / name)
    return written


def capture_rows(values: Iterable[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    """The points of a sweep (its saved values) that carry a flow-field game's capture probabilities."""
    return [v for v in values if "capture_probability_open_loop" in v.get("metrics", {})]


def plot_capture_sweep(
    points: Sequence[tuple[float, Mapping[str, Any]]], parameter: str, path: Path, problem: str = ""
) -> Path:
    """Capture probability at ``T̂`` against ``parameter`` — ``points`` are (value, metrics) — in
    open loop and under each solution concept of :data:`LOOPS`, eq. 5.39 and the Monte Carlo with its
    interval (Fig. 5.2); ``problem`` heads the title."""
    points = sorted(points, key=lambda p: p[0])
    x = np.array([value for value, _ in points])
    fig, ax = plt.subplots(figsize=(6, 4))
    for loop, marker in LOOPS:
        if not all(f"capture_probability_{loop}" in m for _, m in points):
            continue
        ax.plot(x, [m[f"capture_probability_{loop}"] for _, m in points], marker + "-", label=loop)
        carlo = [m.get("monte_carlo_capture_probability", {}).get(loop) for _, m in points]
        if all(carlo):
            est = np.array([c["estimate"] for c in carlo])
            err = np.array([[c["estimate"] - c["low"], c["high"] - c["estimate"]] for c in carlo]).T
            ax.errorbar(x, est, yerr=err, fmt="x", color="gray", label=f"{loop} Monte Carlo")
    ax.set_xlabel(parameter)
    ax.set_ylabel("capture probability at T̂")
    head = f"{problem}: " if problem else ""
    ax.set_title(f"{head}capture probability at T̂ against {parameter} (eq. 5.39)", fontsize="medium")
    ax.legend(**LEGEND_RIGHT)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return Path(path)
