"""Plots of a ``pursuit_scenario`` Result (thesis Figs. 3.5–3.7).

``trajectories.png``: paths to the end with the final positions, initial Apollonius circles (CB) or
refined Apollonius curves (PP) of every evader, and the Voronoi cells of the final pursuer
positions. ``snapshots.png``: three instants as in Fig. 3.7 with Voronoi cells, active pursuers
(blue squares), redundant ones (cyan), free evaders (red triangles) and captured ones (magenta).
Every frame labels the agents (P1…, E1…) and draws the current assignments (who chases whom).
With ``animate``, ``scenario.gif`` (and ``scenario.mp4`` when ffmpeg is installed).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib import animation
from matplotlib.axes import Axes
from scipy.spatial import QhullError, Voronoi, voronoi_plot_2d

from gamespec.plotting import LEGEND_RIGHT, headline
from gamespec.pursuit.apollonius import apollonius_circles
from gamespec.pursuit.bearing import line_of_sight_angles
from gamespec.result import Result
from gamespec_geometric.apollonius import refined_pp_radius

_FRAMES = 60


def _voronoi(ax: Axes, points: np.ndarray) -> None:
    """Voronoi cells of the pursuers, when there are enough distinct ones to draw them."""
    if len(points) < 3:
        return
    try:
        diagram = Voronoi(points)
    except QhullError:
        return
    voronoi_plot_2d(
        diagram,
        ax=ax,
        show_points=False,
        show_vertices=False,
        line_colors="0.8",
        line_width=0.7,
        line_style="solid",
    )
    ax.plot([], [], color="0.8", lw=0.7, label="Voronoi cells of the pursuers")


def _capture_regions(ax: Axes, result: Result) -> None:
    """Initial Apollonius circles (CB) or refined Apollonius curves (PP) of the pursuers allocated
    to each evader at t = 0 (one colour per evader; redundant pursuers' regions are left out)."""
    pursuers = result.states["pursuers"][0]
    u = np.asarray(result.metrics["pursuer_speeds"])
    allocated = result.arrays["allocation"][0]
    angles = np.linspace(-np.pi, np.pi, 361)
    kinds = np.asarray(
        result.metrics.get("pursuer_strategies", [result.metrics["pursuit_strategy"]] * len(u))
    )
    evaders = zip(result.states["evaders"][0], result.metrics["evader_speeds"], strict=True)
    for j, (evader, v) in enumerate(evaders):
        colour = plt.get_cmap("tab10")(j % 10)
        mine = (allocated == j) & (kinds == "cb")
        circles = apollonius_circles(pursuers[mine], evader, u[mine], v)
        for center, radius in zip(circles.centers, circles.radii, strict=True):
            ax.add_patch(plt.Circle(center, radius, fill=False, lw=0.7, color=colour, alpha=0.7))
        mine = (allocated == j) & (kinds == "pp")
        if not mine.any():
            continue
        distance = np.linalg.norm(pursuers[mine] - evader, axis=1)
        radius = refined_pp_radius(distance[:, None], angles[None, :], u[mine][:, None], v)
        direction = line_of_sight_angles(pursuers[mine], evader)[:, None] + angles[None, :]
        ax.plot(
            (evader[0] + radius * np.cos(direction)).T,
            (evader[1] + radius * np.sin(direction)).T,
            lw=0.7,
            color=colour,
            alpha=0.7,
        )


def _frame(ax: Axes, result: Result, k: int, limits: tuple[np.ndarray, np.ndarray]) -> None:
    """Players at step ``k``: trails, Voronoi cells, active/redundant pursuers, free/captured evaders,
    agent labels (P1…, E1…) and the current assignments (a dashed line from each active pursuer to
    the evader it is allocated to)."""
    pursuers, evaders = result.states["pursuers"], result.states["evaders"]
    ax.clear()
    _voronoi(ax, pursuers[k])
    ax.plot(pursuers[: k + 1, :, 0], pursuers[: k + 1, :, 1], color="tab:blue", lw=0.8, alpha=0.6)
    ax.plot(evaders[: k + 1, :, 0], evaders[: k + 1, :, 1], color="tab:red", lw=0.8, alpha=0.6)
    allocation = result.arrays["allocation"][k]
    active = allocation >= 0
    for i in np.flatnonzero(active):
        j = int(allocation[i])
        colour = plt.get_cmap("tab10")(j % 10)
        ax.annotate(
            "",
            evaders[k, j],
            pursuers[k, i],
            arrowprops={
                "arrowstyle": "->",
                "color": colour,
                "lw": 1.0,
                "ls": "--",
                "shrinkA": 3,
                "shrinkB": 5,
            },
        )
    ax.plot([], [], "--", color="0.3", lw=1.0, label="assignment: pursuer → evader")
    ax.plot(*pursuers[k][active].T, "s", color="blue", ms=6, label="active pursuer")
    ax.plot(*pursuers[k][~active].T, "s", color="cyan", ms=6, label="redundant pursuer")
    t = result.time[k]
    caught = np.array([c is not None and c <= t for c in result.metrics["capture_times"]])
    ax.plot(*evaders[k][~caught].T, "^", color="red", ms=7, label="free evader")
    ax.plot(*evaders[k][caught].T, "^", color="magenta", ms=7, label="captured evader")
    for prefix, points in (("P", pursuers[k]), ("E", evaders[k])):
        for n, point in enumerate(points):
            ax.annotate(f"{prefix}{n + 1}", point, textcoords="offset points", xytext=(4, 3), fontsize=7)
    ax.set_xlim(limits[0][0], limits[1][0])
    ax.set_ylim(limits[0][1], limits[1][1])
    ax.set_aspect("equal")
    ax.set(xlabel="x", ylabel="y")
    ax.set_title(f"t = {t:.2f}: {int(caught.sum())} of {len(caught)} evaders captured", fontsize="medium")


def _limits(result: Result) -> tuple[np.ndarray, np.ndarray]:
    everyone = np.concatenate(
        [result.states["pursuers"].reshape(-1, 2), result.states["evaders"].reshape(-1, 2)]
    )
    low, high = everyone.min(axis=0), everyone.max(axis=0)
    pad = 0.08 * float(np.max(high - low)) + 0.5
    return low - pad, high + pad


def _outcome(result: Result) -> str:
    """``all 5 captured by t = 6.51`` or ``4 of 6 captured, E2, E5 escaped``."""
    times = result.metrics["capture_times"]
    escaped = [f"E{j + 1}" for j, c in enumerate(times) if c is None]
    if not escaped:
        return f"all {len(times)} captured by t = {max(times):.4g}"
    return f"{len(times) - len(escaped)} of {len(times)} captured, {', '.join(escaped)} escaped"


def plot_scenario(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """Write the scenario's figures (and animation) into ``output_dir``; return their paths."""
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    limits = _limits(result)
    last = len(result.time) - 1
    written = []

    fig, ax = plt.subplots(figsize=(9, 7))
    _frame(ax, result, last, limits)
    _capture_regions(ax, result)
    ax.set_title(
        f"{headline(result)}: {_outcome(result)}\npaths to t = {result.time[last]:.2f} (markers: positions "
        "then), Apollonius regions of the allocation at t = 0",
        fontsize="medium",
    )
    ax.legend(**LEGEND_RIGHT)
    written.append(output_dir / "trajectories.png")
    fig.savefig(written[-1], dpi=120, bbox_inches="tight")
    plt.close(fig)

    fig, axes = plt.subplots(1, 3, figsize=(17, 5.6))
    for ax, k in zip(axes, (0, last // 2, last), strict=True):
        _frame(ax, result, k, limits)
    axes[-1].legend(**LEGEND_RIGHT)
    fig.suptitle(f"{headline(result)}: {_outcome(result)}")
    written.append(output_dir / "snapshots.png")
    fig.savefig(written[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)

    if animate:
        written.extend(_animate(result, output_dir, limits))
    return written


def _animate(result: Result, output_dir: Path, limits: tuple[np.ndarray, np.ndarray]) -> list[Path]:
    """GIF (Pillow) and, when ffmpeg is installed, MP4 of the game, at most ``_FRAMES`` frames: the
    time and captures in the title, a legend, and trails that grow frame by frame."""
    frames = np.unique(np.linspace(0, len(result.time) - 1, _FRAMES).astype(int))
    fig, ax = plt.subplots(figsize=(8.5, 6))
    fig.subplots_adjust(left=0.08, right=0.68)

    def draw(k: int) -> None:
        _frame(ax, result, int(k), limits)
        ax.set_title(f"{result.problem} — {ax.get_title()}", fontsize="small")
        ax.legend(**LEGEND_RIGHT)

    movie = animation.FuncAnimation(fig, draw, frames=frames)
    written = [output_dir / "scenario.gif"]
    movie.save(written[0], writer=animation.PillowWriter(fps=15))
    if animation.writers.is_available("ffmpeg"):
        written.append(output_dir / "scenario.mp4")
        movie.save(written[1], writer=animation.FFMpegWriter(fps=15))
    plt.close(fig)
    return written
