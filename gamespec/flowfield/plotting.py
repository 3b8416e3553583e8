"""Plots of a ``flow_field_game`` Result (registered as that kind's plotter), red the pursuer and
blue the evader as in the thesis:

- ``reachable_sets.png``: both reachable sets at ``T̂`` (the upper level read, or the extremal
  fronts) with the nominal paths and the capture point (Figs. 5.1, 5.4(a));
- ``dispersion.png``: closed-loop Monte Carlo paths of both agents (Figs. 5.3, 5.4(b));
- ``capture_probability.png``: eq. 5.39 per step, open and closed loop.

:func:`plot_noise_study` draws the capture probability at ``T̂`` against the noise level for a
list of Results (Fig. 5.2).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes

from gamespec.result import Result

COLORS = ("tab:red", "tab:blue")


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
        ax.plot(path[:, 0], path[:, 1], "--", color=color, label=f"{name} (nominal)")
        ax.plot(*path[0], "o", color=color)
    ax.plot(*result.metrics["capture_point"], "k*", ms=10, label="capture point")
    ax.set_title(f"reachable sets at T̂ = {result.metrics['capture_time']:.3f} (level {_level(result)})")


def _dispersion(ax: Axes, result: Result) -> None:
    paths = result.arrays["monte_carlo_closed_loop"]
    for i, color in enumerate(COLORS):
        for sample in paths:
            ax.plot(sample[:, 2 * i], sample[:, 2 * i + 1], color=color, lw=0.3, alpha=0.3)
    for path in result.arrays["nominal_positions"]:
        ax.plot(path[:, 0], path[:, 1], "k--", lw=0.8)
    ax.set_title("closed-loop trajectory dispersion")


def _probability(ax: Axes, result: Result) -> None:
    t = result.time[1:]
    ax.plot(t, result.arrays["capture_probability_open_loop"], "o-", label="open loop")
    ax.plot(t, result.arrays["capture_probability_closed_loop"], "s-", label="closed loop")
    ax.set_xlabel("t")
    ax.set_ylabel("capture probability (eq. 5.39)")


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
        fig, ax = plt.subplots(figsize=(6, 4.5))
        draw(ax, result)
        if name != "dispersion.png":
            ax.legend(fontsize=8)
        if name != "capture_probability.png":
            ax.set_aspect("equal")
        fig.tight_layout()
        fig.savefig(output_dir / name, dpi=120)
        plt.close(fig)
        written.append(output_dir / name)
    return written


def plot_noise_study(results: Sequence[Result], parameter: str, path: Path) -> Path:
    """Capture probability at ``T̂`` against ``parameter``, open vs closed loop, eq. 5.39 and the
    Monte Carlo with its interval (Fig. 5.2)."""
    x = np.array([r.parameters[parameter] for r in results])
    fig, ax = plt.subplots(figsize=(6, 4))
    for loop, marker in (("open_loop", "o"), ("closed_loop", "s")):
        ax.plot(x, [r.metrics[f"capture_probability_{loop}"] for r in results], marker + "-", label=loop)
        carlo = [r.metrics.get("monte_carlo_capture_probability", {}).get(loop) for r in results]
        if all(carlo):
            est = np.array([c["estimate"] for c in carlo])
            err = np.array([[c["estimate"] - c["low"], c["high"] - c["estimate"]] for c in carlo]).T
            ax.errorbar(x, est, yerr=err, fmt="x", color="gray", label=f"{loop} Monte Carlo")
    ax.set_xlabel(parameter)
    ax.set_ylabel("capture probability at T̂")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)
