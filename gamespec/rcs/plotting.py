"""Figures of §6.4: |S_g| and |S_r| over a grid of agent positions (Fig. 6.6), the path with the
obstacles drawn where they are (Figs. 6.7(a), 6.8), S_g and S_r along the solution (Fig. 6.7(b, c))
with the Monte Carlo's collision probability along the path,
several weight levels overlaid (paths: Figs. 6.7(a), 6.8; controls: Fig. 6.9(b)), and the study's
trade-off (Fig. 6.11). Plots read Results (and, for the map, the obstacle geometry) only.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import sympy as sp

from gamespec.desensitize.plotting import collision_note
from gamespec.plotting import LEGEND_RIGHT, headline
from gamespec.rcs.obstacles import avoidance
from gamespec.rcs.relevance import relevance
from gamespec.rcs.spec import Obstacle
from gamespec.result import Result
from gamespec.symbolic.calculus import numeric_function
from gamespec.symbolic.language import SYMPY, TIME, symbol

OBSTACLE_SNAPSHOTS = 5
"""How many times the obstacles are drawn along a path (agent and obstacle in the same colour)."""


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def sensitivity_map(
    center: tuple[float, float] = (0.0, 1.0),
    radius: float = 0.6,
    t: float = 1.0,
    rho: float = 0.25,
    power: float = 1.0,
    choice: str = "logistic_derivative",
    extent: float = 3.0,
    points: int = 201,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(X, Y, g, |S_g|, |S_r|) over agent positions, the obstacle at ``center`` at time ``t`` moving
    along y at speed ρ (Fig. 6.6's setting by default: (0, 1), r_o = 0.6, t = 1): S_g = ∂g/∂ρ
    (eq. 6.40; eq. 6.42 for β ≠ 1), S_r = r(g) S_g. At the obstacle's centre (inside the infeasible
    disc the figure leaves white) eq. 6.42 divides by zero: that value is not drawn, and no warning
    is printed for it. The obstacle's numbers and its speed's name ``rho`` are built in SymPy as
    they stand, no text parsed (issue 27, item 3)."""
    x, y, r = symbol("x"), symbol("y"), symbol("rho")
    start = (center[0], center[1] - rho * t)
    obstacle = Obstacle(center=start, velocity=(0.0, "rho"), radius=radius)
    g = avoidance(obstacle, (x, y), sp.sympify(power), lambda v: r if v == "rho" else SYMPY.number(v), 0.0)
    S_g = sp.diff(g, r)
    f = numeric_function([g, S_g, relevance(choice, g) * S_g], [x, y, r, TIME])
    X, Y = np.meshgrid(
        np.linspace(center[0] - extent, center[0] + extent, points),
        np.linspace(center[1] - extent, center[1] + extent, points),
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        G, Sg, Sr = (np.broadcast_to(v, X.shape) for v in f(X, Y, rho, t))
    return X, Y, G, np.abs(Sg), np.abs(Sr)


def plot_sensitivity_map(path: Path, heading: str = "", **setting) -> Path:
    """Fig. 6.6: |S_g| and |S_r| side by side, the infeasible disc (g > 0) left white; ``heading``
    heads the figure (a Result's :func:`~gamespec.plotting.headline`)."""
    plt = _pyplot()
    X, Y, G, Sg, Sr = sensitivity_map(**setting)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.4))
    for ax, values, title in ((axes[0], Sg, "|S_g|"), (axes[1], Sr, "|S_r|")):
        shown = np.ma.masked_where(G > 0, values)
        mesh = ax.pcolormesh(X, Y, shown, shading="auto", cmap="viridis")
        fig.colorbar(mesh, ax=ax)
        ax.set_title(title)
        ax.set_aspect("equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
    fig.suptitle(
        f"{heading}\nsensitivity of the avoidance constraint to ρ about the agent's positions".lstrip(),
        fontsize="medium",
    )
    fig.tight_layout()
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def _obstacle_names(result: Result) -> list[str]:
    return list(result.metrics.get("obstacles", {}))


def _draw_path(ax, result: Result, label: str | None = None, color=None, snapshots: bool = True) -> None:
    x, y = result.states["x"], result.states.get("y", np.zeros_like(result.states["x"]))
    line = ax.plot(x, y, "-", color=color, label=label)[0]
    if not snapshots:
        return
    plt = _pyplot()
    t = np.asarray(result.time)
    picks = np.linspace(0, t.size - 1, OBSTACLE_SNAPSHOTS).astype(int)
    colors = plt.cm.plasma(np.linspace(0, 0.85, picks.size))
    for name in _obstacle_names(result):
        ox, oy = result.arrays[f"obstacle_{name}_x"], result.arrays[f"obstacle_{name}_y"]
        ax.plot(ox, oy, ":", color="0.5", lw=0.8)
        for k, c in zip(picks, colors, strict=True):
            ax.add_patch(plt.Circle((ox[k], oy[k]), result.metrics["obstacles"][name], color=c, alpha=0.25))
            ax.plot(x[k], y[k], "o", color=c, markersize=4)
    line.set_zorder(3)


def _draw_samples(ax, result: Result) -> None:
    """Where the uncertainty is: each obstacle's centre for the Monte Carlo's kept draws at the
    agent's closest approach to its nominal centre (``metrics.obstacle_samples``), the draws whose
    open-loop run collided (anywhere along it) in red, the others in grey, and the nominal
    obstacle's outline and the agent there."""
    plt = _pyplot()
    verdicts = result.arrays.get("monte_carlo_draw_violated")
    for name, entry in result.metrics.get("obstacle_samples", {}).items():
        if f"obstacle_{name}_sampled_x" not in result.arrays or verdicts is None:
            continue
        sx, sy = result.arrays[f"obstacle_{name}_sampled_x"], result.arrays[f"obstacle_{name}_sampled_y"]
        hit = verdicts > 0
        when = f"{name} at t = {entry['time']:.3g}"
        for chosen, colour, what in ((hit, "tab:red", "collided"), (~hit, "0.35", "clear")):
            ax.scatter(
                sx[chosen],
                sy[chosen],
                s=9,
                color=colour,
                alpha=0.6,
                zorder=4,
                label=f"sampled centre, {when}: {what} ({np.count_nonzero(chosen)} of {hit.size})",
            )
        k = int(np.argmin(np.abs(np.asarray(result.time) - entry["time"])))
        centre = (result.arrays[f"obstacle_{name}_x"][k], result.arrays[f"obstacle_{name}_y"][k])
        radius = result.metrics["obstacles"][name]
        ax.add_patch(
            plt.Circle(centre, radius, fill=False, ls="--", color="k", label=f"nominal {when}", zorder=4)
        )


def plot_rcs(result: Result, output_dir: Path) -> list[Path]:
    """A Result of the ``rcs`` transform: the path among the obstacles with the obstacles' sampled
    centres at the closest approach, S_g and S_r along it, and the map of Fig. 6.6 about its first
    obstacle at the time of closest approach."""
    plt = _pyplot()
    output_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    if "x" in result.states and _obstacle_names(result):
        fig, ax = plt.subplots(figsize=(6.5, 5))
        _draw_path(ax, result, label="nominal path")
        _draw_samples(ax, result)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_title(
            f"{headline(result)}\nobstacles at {OBSTACLE_SNAPSHOTS} times (same colour as the agent)"
            + (
                "; sampled obstacles at the closest approach"
                if result.metrics.get("obstacle_samples")
                else ""
            )
            + collision_note(result).replace(", ", "\n", 1),
            fontsize="medium",
        )
        if ax.get_legend_handles_labels()[0]:
            ax.legend(**LEGEND_RIGHT)
        paths.append(output_dir / f"{result.problem}_obstacles.png")
        fig.savefig(paths[-1], dpi=120, bbox_inches="tight")
        plt.close(fig)
    keys = sorted(k for k in result.arrays if k.startswith(("S_g", "S_r")))
    if keys:
        along = "monte_carlo_violated" in result.arrays
        fig, axes = plt.subplots(3 if along else 2, 1, figsize=(7, 7.5 if along else 5.5), sharex=True)
        for k in keys:
            axes[0 if k.startswith("S_r") else 1].plot(result.time, np.abs(result.arrays[k]), label=k)
        axes[0].set_ylabel("|S_r|")
        axes[1].set_ylabel("|S_g|")
        if along:
            _collision_along(axes[2], result)
        axes[-1].set_xlabel("t")
        for ax in axes:
            ax.legend(**LEGEND_RIGHT)
        fig.suptitle(headline(result), fontsize="medium")
        paths.append(output_dir / f"{result.problem}_rcs.png")
        fig.savefig(paths[-1], dpi=120, bbox_inches="tight")
        plt.close(fig)
    names = _obstacle_names(result)
    if names and "x" in result.states and "y" in result.states:
        name = names[0]
        ox, oy = result.arrays[f"obstacle_{name}_x"], result.arrays[f"obstacle_{name}_y"]
        k = int(np.argmin(np.hypot(result.states["x"] - ox, result.states["y"] - oy)))
        speed = (oy[-1] - oy[0]) / max(float(result.t_final) - float(result.time[0]), 1e-12)
        setting = {
            "center": (float(ox[k]), float(oy[k])),
            "radius": result.metrics["obstacles"][name],
            "t": max(float(result.time[k]), 1e-9),
            "rho": float(speed),
            "power": result.metrics.get("obstacle_power", 1.0),
            "choice": result.metrics["rcs"]["relevance"],
        }
        paths.append(
            plot_sensitivity_map(
                output_dir / f"{result.problem}_sensitivity_map.png", headline(result), **setting
            )
        )
    return paths


def _collision_along(ax, result: Result) -> None:
    """P_c along the path: the fraction of the open-loop Monte Carlo's samples that have collided
    by each time (its last value is the collision probability)."""
    mc = result.metrics["monte_carlo"]
    ax.plot(
        result.arrays["monte_carlo_time"],
        result.arrays["monte_carlo_violated"],
        color="tab:red",
        label=f"collided by t ({mc['samples']} samples)",
    )
    ax.set_ylabel("P_c by t")
    ax.set_ylim(-0.02, max(0.05, 1.1 * float(np.max(result.arrays["monte_carlo_violated"]))))
    ax.set_title("collision probability along the path (open-loop Monte Carlo)", fontsize="medium")


def plot_levels(
    results: Sequence[Result], labels: Sequence[str], path: Path, control: str | None = None
) -> Path:
    """Several weight levels overlaid: the paths with the obstacles (Figs. 6.7(a), 6.8), or one
    control against time when ``control`` is given (Fig. 6.9(b))."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 5))
    for i, (result, label) in enumerate(zip(results, labels, strict=True)):
        if control is not None:
            tc = result.control_time if result.control_time is not None else result.time
            ax.plot(tc, result.controls[control], "-", label=label)
            ax.set_xlabel("t")
            ax.set_ylabel(control)
        else:
            _draw_path(ax, result, label=label, color=f"C{i}", snapshots=i == 0)
            ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(
        "paths at each weight level" if control is None else f"{control} at each weight level",
        fontsize="medium",
    )
    ax.legend(**LEGEND_RIGHT)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def plot_study(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """Fig. 6.11: t_f against collision probability per N (α on the points), and the kept paths
    per N with the obstacles' tracks and their positions when they cross y = 0."""
    plt = _pyplot()
    output_dir.mkdir(parents=True, exist_ok=True)
    table = [r for r in result.metrics["table"] if r.get("t_final") is not None]
    counts = sorted({r["obstacles"] for r in table})
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for n in counts:
        rows = sorted((r for r in table if r["obstacles"] == n), key=lambda r: r["alpha"])
        ax.plot(
            [r["t_final"] for r in rows], [r["collision_probability"] for r in rows], "o-", label=f"N = {n}"
        )
        for r in rows:
            ax.annotate(f"α={r['alpha']:g}", (r["t_final"], r["collision_probability"]), fontsize=7)
    ax.set_xlabel("t_f")
    ax.set_ylabel("collision probability")
    ax.set_title(
        f"{headline(result)}\ntravel time against collision probability (Fig. 6.11)", fontsize="medium"
    )
    ax.legend(**LEGEND_RIGHT)
    ax.grid(alpha=0.3)
    paths = [output_dir / f"{result.problem}_tradeoff.png"]
    fig.savefig(paths[0], dpi=120, bbox_inches="tight")
    plt.close(fig)
    fig, axes = plt.subplots(len(counts), 1, figsize=(8, 2.6 * len(counts)), squeeze=False)
    radius = result.metrics.get("radius", 1.0)
    for ax, n in zip(axes[:, 0], counts, strict=True):
        for x, _y0, _d in result.metrics["layout"][str(n)]:
            ax.axvline(x, color="0.7", ls=":", lw=0.8)
            ax.add_patch(plt.Circle((x, 0.0), radius, color="0.6", alpha=0.3))
        for r in sorted((r for r in table if r["obstacles"] == n), key=lambda r: r["alpha"]):
            tag = f"N{n}_alpha{r['alpha']:g}"
            if f"path_{tag}_x" in result.arrays:
                ax.plot(
                    result.arrays[f"path_{tag}_x"],
                    result.arrays[f"path_{tag}_y"],
                    label=f"α = {r['alpha']:g}",
                )
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(f"N = {n} (obstacles drawn where they cross y = 0)", fontsize=9)
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.legend(**LEGEND_RIGHT)
    fig.suptitle(headline(result), fontsize="medium")
    fig.tight_layout()
    paths.append(output_dir / f"{result.problem}_paths.png")
    fig.savefig(paths[-1], dpi=120, bbox_inches="tight")
    plt.close(fig)
    return paths
