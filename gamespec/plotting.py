"""Plots of ``optimal_control`` Results: states, controls and, for planar problems, the path.

Plotters read Results only (never solver objects) and are registered per kind in the
``gamespec.plotters`` entry-point group; :func:`plot_result` dispatches on ``result.kind``.
"""

from __future__ import annotations

from pathlib import Path

from gamespec import registry
from gamespec.result import Result

PLANAR_PAIRS = (("x", "y"), ("x1", "x2"), ("x_E", "y_E"))


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_trajectories(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """States and controls against time, and the planar path when the states hold one."""
    plt = _pyplot()
    output_dir.mkdir(parents=True, exist_ok=True)
    rows = 2 if result.controls else 1
    fig, axes = plt.subplots(rows, 1, figsize=(7, 3.2 * rows), sharex=True, squeeze=False)
    for name, values in result.states.items():
        axes[0, 0].plot(result.time, values, label=name)
    axes[0, 0].set_ylabel("states")
    axes[0, 0].legend(loc="best")
    if result.controls:
        tc = result.control_time if result.control_time is not None else result.time
        for name, values in result.controls.items():
            axes[1, 0].plot(tc, values, ".-", label=name, markersize=3)
        axes[1, 0].set_ylabel("controls")
        axes[1, 0].legend(loc="best")
    axes[-1, 0].set_xlabel("t")
    objective = "" if result.objective is None else f", J = {result.objective:.6g}"
    fig.suptitle(f"{result.problem} — {result.backend}, {result.status.value}{objective}")
    fig.tight_layout()
    paths = [output_dir / f"{result.problem}_time.png"]
    fig.savefig(paths[0], dpi=120)
    plt.close(fig)
    for xs, ys in PLANAR_PAIRS:
        if xs in result.states and ys in result.states:
            fig, ax = plt.subplots(figsize=(5.5, 5))
            ax.plot(result.states[xs], result.states[ys], "-")
            ax.plot(result.states[xs][0], result.states[ys][0], "o", label="start")
            ax.plot(result.states[xs][-1], result.states[ys][-1], "s", label="end")
            ax.set_xlabel(xs)
            ax.set_ylabel(ys)
            ax.set_aspect("equal", adjustable="datalim")
            ax.legend(loc="best")
            ax.grid(alpha=0.3)
            path = output_dir / f"{result.problem}_path.png"
            fig.savefig(path, dpi=120)
            plt.close(fig)
            paths.append(path)
            break
    if "desensitization" in result.metrics:
        from gamespec.desensitize.plotting import plot_desensitized

        paths += plot_desensitized(result, output_dir)
    if "rcs" in result.metrics:
        from gamespec.rcs.plotting import plot_rcs

        paths += plot_rcs(result, output_dir)
    return paths


def plot_result(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """Dispatch to the plotter registered for the Result's kind."""
    plotter = registry.load("gamespec.plotters", result.kind)
    return plotter(result, output_dir, animate=animate)
