"""Figures of ``differential_game`` Results (Figs. 7.1–7.2): the players' paths, the obstacle where it
truly is (filled) and where the pursuer believes it is (dashed), its initial position (dotted), and
each step's look-ahead trajectories (green); with ``animate`` a GIF of the run, step by step. A
value function (the ``hji`` backend) is drawn by :mod:`gamespec.games.capture_plot`.

A moving obstacle is drawn at the times that matter: at the end of the run, and at the closest
approach (the sample where a player's position comes nearest the true obstacle's centre), with the
players' positions at that time, so that a path crossing the believed circle where the obstacle was
not yet is not read as a collision. The GIF has a frame per receding-horizon step and one at the
run's last sample (the capture or the collision).

A receding-horizon Result names its position states in ``metrics.figure``; any other Result (an
open-loop game) gets the ``optimal_control`` plots of its trajectories, and the x–y figure of the
file's ``plot.planar`` pairs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gamespec.plotting import LEGEND_RIGHT, headline, plot_trajectories
from gamespec.result import Result

COLORS = ("tab:blue", "tab:red", "tab:purple", "tab:orange")
APPROACH_COLOURS = ("tab:olive", "tab:cyan", "tab:brown", "tab:pink")
"""The obstacles and players at each player's closest approach."""


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _obstacles(result: Result) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """``true`` and each believing player's obstacle centre along the run."""
    out = {}
    for key in result.arrays:
        parts = key.split("/")
        if parts[0] == "obstacle" and parts[2] == "x":
            out[parts[1]] = (result.arrays[key], result.arrays[f"obstacle/{parts[1]}/y"])
    return out


def closest_approaches(result: Result) -> dict[str, int]:
    """Per player, the sample at which its position is nearest the true obstacle's centre (none
    without an obstacle)."""
    obstacles = _obstacles(result)
    if "true" not in obstacles or result.metrics["figure"]["obstacle_radius"] is None:
        return {}
    ox, oy = obstacles["true"]
    return {
        player: int(np.nanargmin(np.hypot(result.states[px] - ox, result.states[py] - oy)))
        for player, (px, py) in _positions(result).items()
    }


def _positions(result: Result) -> dict[str, tuple[str, str]]:
    return {player: tuple(pair) for player, pair in result.metrics["figure"]["positions"].items()}


def _obstacles_at(ax, result: Result, k: int, when: str, colours: tuple[str, str]) -> None:
    """The true obstacle (filled, the first colour) and each believed one (dashed, the second) at
    sample ``k``, named by ``when``."""
    plt = _pyplot()
    radius = result.metrics["figure"]["obstacle_radius"]
    for name, (bx, by) in _obstacles(result).items():
        true = name == "true"
        label = f"obstacle {when} (true)" if true else f"obstacle {when} ({name}'s belief)"
        centre = (bx[k], by[k])
        if true:
            patch = plt.Circle(centre, radius, alpha=0.5, color=colours[0], label=label)
        else:
            patch = plt.Circle(centre, radius, fill=False, ls="--", color=colours[1], label=label)
        ax.add_patch(patch)


def _draw(ax, result: Result, upto: int, step: int | None, approaches: dict[str, int] | None = None) -> None:
    """The run up to sample ``upto``; the look-ahead of ``step`` (every step's when None); the
    obstacles and the players also at each player's closest approach in ``approaches`` (those at
    the first or the last sample drawn are drawn already)."""
    plt = _pyplot()
    figure = result.metrics["figure"]
    radius = figure["obstacle_radius"]
    obstacles = _obstacles(result)
    if radius is not None and "true" in obstacles:
        ox, oy = obstacles["true"]
        ax.add_patch(
            plt.Circle((ox[0], oy[0]), radius, fill=False, ls=":", color="grey", label="obstacle at t = 0")
        )
        _obstacles_at(ax, result, upto, f"at t = {result.time[upto]:.2f}", ("grey", "k"))
    shown = {k: player for player, k in (approaches or {}).items() if 0 < k < upto}
    for (k, player), colour in zip(sorted(shown.items()), APPROACH_COLOURS, strict=False):
        _obstacles_at(
            ax, result, k, f"at {player}'s closest approach, t = {result.time[k]:.2f}", (colour, colour)
        )
        for px, py in _positions(result).values():
            ax.plot(result.states[px][k], result.states[py][k], "D", color=colour, mfc="none")
    if step is None:
        steps: range | list[int] = range(len(result.control_time))
    else:
        steps = [step] if step < len(result.control_time) else []
    for view in figure["lookahead_players"]:
        px, py = figure["positions"].get(view, (None, None))
        if px is None:
            continue
        xs, ys = result.arrays[f"lookahead/{view}/{px}"], result.arrays[f"lookahead/{view}/{py}"]
        for k in steps:
            ax.plot(xs[k], ys[k], "-", color="tab:green", lw=0.8, alpha=0.6 if step is None else 1.0)
    for (player, (px, py)), color in zip(figure["positions"].items(), COLORS, strict=False):
        x, y = result.states[px], result.states[py]
        ax.plot(x[: upto + 1], y[: upto + 1], "-", color=color, label=player)
        ax.plot(x[0], y[0], "o", color=color, mfc="none")
        ax.plot(x[upto], y[upto], "o", color=color)
    for (k, _), colour in zip(sorted(shown.items()), APPROACH_COLOURS, strict=False):
        ax.plot([], [], "D", color=colour, mfc="none", label=f"players at t = {result.time[k]:.2f}")
    ax.plot([], [], "-", color="tab:green", label="look-ahead")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.grid(alpha=0.3)


def _summary(result: Result) -> str:
    m = result.metrics
    end = f"captured at t = {m['capture_time']:.2f}" if m.get("captured") else f"stopped: {m.get('stop')}"
    return f"{headline(result)}\n{end}"


def plot_game(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """The figures of the module doc; the paths of the files written."""
    if "value" in result.arrays:
        from gamespec.games.capture_plot import plot_capture_region

        return plot_capture_region(result, output_dir)
    if "figure" not in result.metrics:
        return plot_trajectories(result, output_dir, animate=animate)
    plt = _pyplot()
    output_dir.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(7, 6))
    _draw(ax, result, len(result.time) - 1, None, closest_approaches(result))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(_summary(result), fontsize="medium")
    ax.legend(**LEGEND_RIGHT)
    paths = [output_dir / f"{result.problem}_paths.png"]
    fig.savefig(paths[0], dpi=120, bbox_inches="tight")
    plt.close(fig)
    if animate:
        paths.append(_animation(result, output_dir))
    return paths


def _animation(result: Result, output_dir: Path) -> Path:
    """One frame per receding-horizon step (its look-ahead drawn) and one at the last sample."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8.5, 6))
    fig.subplots_adjust(left=0.1, right=0.72)
    samples = [*np.searchsorted(result.time, result.control_time).tolist(), len(result.time) - 1]
    if len(samples) > 1 and samples[-2] >= samples[-1]:
        samples.pop()
    limits = _limits(result)

    def frame(k: int) -> None:
        ax.clear()
        _draw(ax, result, int(samples[k]), k)
        ax.set_xlim(*limits[0])
        ax.set_ylim(*limits[1])
        ax.set_aspect("equal", adjustable="box")
        ax.set_title(f"{result.problem} — t = {result.time[samples[k]]:.2f}")
        ax.legend(**LEGEND_RIGHT)

    anim = FuncAnimation(fig, frame, frames=len(samples))
    path = output_dir / f"{result.problem}.gif"
    anim.save(path, writer=PillowWriter(fps=8))
    plt.close(fig)
    return path


def _limits(result: Result) -> tuple[tuple[float, float], tuple[float, float]]:
    """Axis limits holding every path, look-ahead and obstacle position, with a margin."""
    figure = result.metrics["figure"]
    xs, ys = [], []
    for px, py in figure["positions"].values():
        xs.append(result.states[px])
        ys.append(result.states[py])
        for view in figure["lookahead_players"]:
            xs.append(result.arrays[f"lookahead/{view}/{px}"].ravel())
            ys.append(result.arrays[f"lookahead/{view}/{py}"].ravel())
    for ox, oy in _obstacles(result).values():
        xs.append(ox)
        ys.append(oy)
    margin = (figure["obstacle_radius"] or 0.0) + 0.2
    x, y = np.concatenate(xs), np.concatenate(ys)
    return (np.nanmin(x) - margin, np.nanmax(x) + margin), (np.nanmin(y) - margin, np.nanmax(y) + margin)
