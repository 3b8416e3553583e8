"""Plots of ``engagement`` Results: paths (Figs. 2.9, 2.10a, 2.14a), the regions of non-degeneracy
(Figs. 2.3, 2.5, 2.11) and distances over time (Figs. 2.10b, 2.14b).

Everything is read from the Result: the players' paths re-simulated with the true dynamics
(``arrays["path_*"]``) and the engagement itself (``metrics["engagement"]``).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from gamespec.plotting import LEGEND_RIGHT, as_drawn, headline, no_offsets
from gamespec.pursuit import regions, relay
from gamespec.result import Result
from gamespec.specs.engagement import EngagementSpec

FRAMES = 60
"""Frames of the engagement GIF."""
REGION_COLOURS = {"D1": "#f4cccc", "D2": "#d9e2f3", "N": "#d9ead3"}
PLAYER_COLOURS = ["tab:blue", "tab:red", "tab:green", "tab:orange", "tab:purple", "tab:brown"]


def _engagement(result: Result) -> EngagementSpec:
    return EngagementSpec.model_validate(result.metrics["engagement"])


def _paths(result: Result, spec: EngagementSpec, ax, upto: int | None = None) -> list:
    """The players' paths up to index ``upto`` (all of it by default); returns the current markers."""
    last = len(result.arrays["path_time"]) if upto is None else upto + 1
    captors = set(result.metrics.get("capturing_set", []))
    markers = []
    for i, p in enumerate(spec.pursuers):
        path = result.arrays[f"path_{p.name}"][:last]
        colour = PLAYER_COLOURS[i % len(PLAYER_COLOURS)]
        style = "s" if p.strategy == "stationary" else "-"
        tag = " ∈ P*" if p.name in captors and upto is None else ""
        ax.plot(path[:, 0], path[:, 1], style, color=colour, label=f"{p.name} ({p.strategy}){tag}")
        ax.plot(*path[0], "o", color=colour, mfc="none")
        markers += ax.plot(*path[-1], "o", color=colour)
    evader = result.arrays["path_evader"][:last]
    ax.plot(evader[:, 0], evader[:, 1], "k-", label="evader")
    ax.plot(*evader[0], "ko", mfc="none", label="start (open circles)")
    if upto is None:
        markers += ax.plot(*evader[-1], "kx", ms=9, mew=2, label="capture point")
    else:
        markers += ax.plot(*evader[-1], "k^")
    return markers


def _outcome(result: Result) -> str:
    """``t_c = …, P* = {…}``: the capture time and the capturing set (Definition 2)."""
    captors = ", ".join(result.metrics.get("capturing_set", [])) or "—"
    return f"t_c = {result.t_final:.4f}, P* = {{{captors}}}"


def plot_paths(result: Result, spec: EngagementSpec, path: Path) -> Path:
    """The players' paths up to capture (x: capture point)."""
    fig, ax = plt.subplots(figsize=(7.5, 5))
    _paths(result, spec, ax)
    ax.set(xlabel="x", ylabel="y", aspect="equal")
    ax.set_title(f"{headline(result)}\n{_outcome(result)}", fontsize="medium")
    ax.legend(**LEGEND_RIGHT)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def _window(points: np.ndarray, pad: float = 0.6) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = points.min(axis=0), points.max(axis=0)
    span = max(float(np.max(hi - lo)), 1.0)
    return lo - pad * span, hi + pad * span


def plot_regions(result: Result, spec: EngagementSpec, path: Path) -> Path | None:
    """Fig. 2.3/2.5 (two active pursuers, same strategy) or Fig. 2.11 (relay); None otherwise."""
    players = [np.array(p.position) for p in spec.pursuers]
    e = np.array(spec.evader.position)
    fig, ax = plt.subplots(figsize=(6, 5))
    if spec.is_relay and len(spec.pursuers) == 2:
        active, guard = (players[i] for i in (spec.active_indices[0], 1 - spec.active_indices[0]))
        u = spec.pursuers[spec.active_indices[0]].speed
        vertices = relay.vertices(active, guard, u, spec.evader.speed)
        lo, hi = _window(np.array([active, guard, e, *vertices.values()]), pad=0.2)
        gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], 300), np.linspace(lo[1], hi[1], 300))
        grid = np.stack([gx, gy], axis=-1)
        inside = relay.is_nondegenerate(active, guard, grid, u, spec.evader.speed)
        ax.contourf(gx, gy, inside.astype(float), levels=[0.5, 1.5], colors=[REGION_COLOURS["N"]])
        for name, point in vertices.items():
            ax.plot(*point, "k.")
            ax.annotate(name, point, textcoords="offset points", xytext=(4, 4))
        ax.set_title(f"{headline(result)}\nregion of non-degeneracy N (Prop. 2, green); {_outcome(result)}")
    elif len(spec.pursuers) == 2 and spec.pursuers[0].strategy == spec.pursuers[1].strategy != "stationary":
        strategy = spec.pursuers[0].strategy
        u1, u2 = (p.speed for p in spec.pursuers)
        v = spec.evader.speed
        curves = regions.boundary_curves(strategy, players[0], e, u1, u2, v)
        lo, hi = _window(np.concatenate([*curves.values(), np.array(players)]), pad=0.1)
        gx, gy = np.meshgrid(np.linspace(lo[0], hi[0], 300), np.linspace(lo[1], hi[1], 300))
        labels = regions.classify(strategy, players[0], np.stack([gx, gy], axis=-1), e, u1, u2, v)
        codes = np.select([labels == "D1", labels == "N"], [0.0, 1.0], 2.0)
        colours = [REGION_COLOURS[k] for k in ("D1", "N", "D2")]
        ax.contourf(gx, gy, codes, levels=[-0.5, 0.5, 1.5, 2.5], colors=colours)
        for name, points in curves.items():
            ax.plot(points[:, 0], points[:, 1], "k--", linewidth=0.8)
            ax.annotate(name, points[len(points) // 4], textcoords="offset points", xytext=(4, 4))
        ax.set_title(
            f"{headline(result)}\nregions D1 (red), N (green), D2 (blue) for P2 ({strategy}), "
            f"P2 in {result.metrics.get('region') or '—'}; {_outcome(result)}"
        )
    else:
        plt.close(fig)
        return None
    _paths(result, spec, ax)
    ax.set(xlabel="x", ylabel="y", aspect="equal")
    ax.title.set_fontsize("medium")
    ax.legend(**LEGEND_RIGHT)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def plot_distances(result: Result, spec: EngagementSpec, path: Path) -> Path:
    """r_i(t) (re-simulated) against the capture radius ε and, with two or more pursuers, a second
    panel: S = ½(r1² − r2²) for relay (Fig. 2.14b), else each r_i − min_j r_j (with two pursuers
    |r1 − r2|, Fig. 2.10b), which vanishes at t_c for every pursuer of the capturing set."""
    t = result.arrays["path_time"]
    evader = result.arrays["path_evader"]
    dist = {p.name: np.linalg.norm(evader - result.arrays[f"path_{p.name}"], axis=1) for p in spec.pursuers}
    rows = 2 if len(dist) > 1 else 1
    fig, axes = plt.subplots(rows, 1, figsize=(7.5, 2.6 + 2.4 * rows), sharex=True, squeeze=False)
    top = axes[0, 0]
    for i, (name, d) in enumerate(dist.items()):
        top.plot(t, d, color=PLAYER_COLOURS[i % len(PLAYER_COLOURS)], label=f"r to {name}")
    top.axhline(spec.capture_radius, color="k", lw=0.8, ls=":", label=f"ε = {spec.capture_radius:g}")
    top.set(ylabel="distance to the evader")
    top.set_title(f"{headline(result)}\n{_outcome(result)}", fontsize="medium")
    top.legend(**LEGEND_RIGHT)
    if rows == 2:
        bottom = axes[1, 0]
        if spec.is_relay:
            r1, r2 = dist.values()
            bottom.plot(t, 0.5 * (r1**2 - r2**2), color="k", label="S")
            bottom.axhline(0.0, color="0.5", lw=0.6)
            bottom.set(ylabel="S = (r1² − r2²)/2")
            bottom.set_title("relay switching function S (Fig. 2.14b)", fontsize="medium")
            arcs = result.metrics.get("arcs", {})
            for key in ("tau1", "tau2"):
                if arcs.get(key) is not None:
                    bottom.axvline(arcs[key], color="grey", linestyle=":", label=f"{key} = {arcs[key]:.4g}")
        else:
            nearest = np.min(np.array(list(dist.values())), axis=0)
            for i, (name, d) in enumerate(dist.items()):
                shown, suffix = as_drawn(d - nearest, name, [])
                bottom.plot(t, shown, color=PLAYER_COLOURS[i % len(PLAYER_COLOURS)], label=name + suffix)
            bottom.set(ylabel="r_i − min_j r_j")
            bottom.set_title(
                "distance above the nearest pursuer's (0 at t_c for the capturing set)", fontsize="medium"
            )
        bottom.legend(**LEGEND_RIGHT)
    axes[-1, 0].set(xlabel="t")
    no_offsets(fig)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return path


def animate_paths(result: Result, spec: EngagementSpec, path: Path) -> Path:
    """A GIF of the players moving to capture (``FRAMES`` frames): paths grow frame by frame, with
    the time shown."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    frames = FRAMES
    fig, ax = plt.subplots(figsize=(8, 4.5))
    fig.subplots_adjust(left=0.1, right=0.7)
    everything = np.concatenate(
        [result.arrays[k] for k in result.arrays if k.startswith("path_") and k != "path_time"]
    )
    lo, hi = everything.min(axis=0), everything.max(axis=0)
    pad = 0.08 * float(np.max(hi - lo)) + 1e-3
    time = result.arrays["path_time"]
    index = np.linspace(0, len(time) - 1, frames).astype(int)

    def update(k: int) -> None:
        ax.clear()
        _paths(result, spec, ax, upto=int(index[k]))
        ax.set(xlim=(lo[0] - pad, hi[0] + pad), ylim=(lo[1] - pad, hi[1] + pad), xlabel="x", ylabel="y")
        ax.set_aspect("equal")
        ax.set_title(
            f"{result.problem} — {result.backend}: t = {time[index[k]]:.3f} of {_outcome(result)}",
            fontsize="small",
        )
        ax.legend(**LEGEND_RIGHT)

    FuncAnimation(fig, update, frames=frames).save(path, writer=PillowWriter(fps=15))
    plt.close(fig)
    return path


def plot_engagement(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """Paths, regions (where defined) and distances of an engagement Result."""
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    if "path_evader" not in result.arrays:
        return []
    spec = _engagement(result)
    written = [plot_paths(result, spec, output_dir / "paths.png")]
    region = plot_regions(result, spec, output_dir / "regions.png")
    written += [region] if region else []
    written.append(plot_distances(result, spec, output_dir / "distances.png"))
    if animate:
        written.append(animate_paths(result, spec, output_dir / "paths.gif"))
    return written
