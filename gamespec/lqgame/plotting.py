"""Plots of an ``lq_stochastic_game`` Result (registered as that kind's plotter).

- ``ellipses.png``: the first two states' plane with the sampled closed-loop trajectories (gray),
  the mean (blue) and its 3σ ellipses, the initial 3σ ellipse (red), the terminal one (thick blue)
  and the target (green, dashed), as in Figs. 4.1–4.3, with a zoom on the terminal ellipse against
  its target;
- ``first_state.png``: the first state against the step with the samples, the mean and red 3σ bars
  at the initial and final steps, as in Fig. 4.5;
- ``convergence.png``: ``ε_k`` and ``ε_ℓ`` per Jacobi iteration (Fig. 4.2(b)), when there are any;
- ``ellipses.gif`` with ``animate``: the ellipses and samples step by step.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter
from matplotlib.axes import Axes

from gamespec.plotting import LEGEND_RIGHT, headline
from gamespec.result import Result

SIGMAS = 3.0


def ellipse_points(mean: np.ndarray, covariance: np.ndarray, sigmas: float = SIGMAS) -> np.ndarray:
    """Points (64, 2) on the ``sigmas``-σ ellipse of a 2-D Gaussian."""
    values, vectors = np.linalg.eigh(covariance)
    angle = np.linspace(0, 2 * np.pi, 64)
    circle = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    return mean + sigmas * circle * np.sqrt(np.maximum(values, 0)) @ vectors.T


def _target(result: Result) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The target mean (NaN entries, i.e. free ones, replaced by the terminal mean) and covariance
    of the first two states, when the file gives them."""
    means = result.arrays["mean"]
    if "target_covariance" not in result.arrays and "target_mean" not in result.arrays:
        return None, None
    target = np.asarray(result.arrays.get("target_mean", means[-1]), dtype=float)
    centre = np.where(np.isnan(target[:2]), means[-1, :2], target[:2])
    covariance = result.arrays.get("target_covariance")
    return centre, None if covariance is None else covariance[:2, :2]


def _ends(ax: Axes, result: Result, *, legend: bool, terminal: bool = True) -> None:
    """The terminal 3σ ellipse (blue, unless ``terminal`` is False) against the target (green):
    what the controller had to meet."""
    means, covs = result.arrays["mean"], result.arrays["covariance"]
    if terminal:
        ax.plot(
            *ellipse_points(means[-1, :2], covs[-1, :2, :2]).T,
            color="tab:blue",
            lw=2.0,
            label="terminal 3σ" if legend else None,
        )
    centre, covariance = _target(result)
    if centre is not None:
        ax.plot(*centre, "+", color="tab:green", ms=10, mew=2, label="target mean" if legend else None)
        if covariance is not None:
            ax.plot(
                *ellipse_points(centre, covariance).T,
                color="tab:green",
                lw=1.6,
                ls="--",
                label="target 3σ" if legend else None,
            )


def _inset(ax: Axes, result: Result) -> None:
    """A zoom on the terminal ellipse, its samples and the target ellipse (they are small)."""
    means, covs = result.arrays["mean"], result.arrays["covariance"]
    zoom = ax.inset_axes([1.06, 0.0, 0.38, 0.5])
    if "samples" in result.arrays:
        ends = result.arrays["samples"][:, -1, :2]
        zoom.plot(ends[:, 0], ends[:, 1], ".", color="0.55", ms=2)
    _ends(zoom, result, legend=False)
    centre, covariance = _target(result)
    spread = [ellipse_points(means[-1, :2], covs[-1, :2, :2])]
    if centre is not None and covariance is not None:
        spread.append(ellipse_points(centre, covariance))
    points = np.concatenate(spread)
    lo, hi = points.min(axis=0), points.max(axis=0)
    pad = 0.15 * float(np.max(hi - lo)) + 1e-9
    zoom.set(xlim=(lo[0] - pad, hi[0] + pad), ylim=(lo[1] - pad, hi[1] + pad))
    zoom.set_title("step N (zoom)", fontsize=7)
    zoom.tick_params(labelsize=6)
    ax.indicate_inset_zoom(zoom, edgecolor="0.4")


def _plane(ax: Axes, result: Result, upto: int | None = None) -> None:
    names = list(result.states)
    means, covs = result.arrays["mean"], result.arrays["covariance"]
    last = len(means) if upto is None else upto + 1
    if "samples" in result.arrays:
        for path in result.arrays["samples"][:, :last, :2]:
            ax.plot(path[:, 0], path[:, 1], color="0.75", lw=0.6)
        ax.plot([], [], color="0.75", lw=0.6, label="Monte Carlo samples")
    ax.plot(means[:last, 0], means[:last, 1], color="tab:blue", lw=1.5, label="mean")
    for k in range(last):
        ax.plot(*ellipse_points(means[k, :2], covs[k, :2, :2]).T, color="tab:blue", lw=0.5, alpha=0.6)
    ax.plot(*ellipse_points(means[0, :2], covs[0, :2, :2]).T, color="tab:red", lw=1.6, label="initial 3σ")
    _ends(ax, result, legend=True, terminal=upto is None or upto == len(means) - 1)
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1])
    ax.set_title(
        f"{headline(result)}\n3σ ellipses of ({names[0]}, {names[1]}), step {last - 1} of {len(means) - 1}",
        fontsize="medium",
    )
    ax.legend(**LEGEND_RIGHT)


def _first_state(ax: Axes, result: Result) -> None:
    name = next(iter(result.states))
    means, covs = result.arrays["mean"][:, 0], result.arrays["covariance"][:, 0, 0]
    steps = np.arange(len(means))
    if "samples" in result.arrays:
        ax.plot(steps, result.arrays["samples"][:, :, 0].T, color="0.75", lw=0.6)
    ax.plot(steps, means, color="tab:blue", lw=1.5, label="mean")
    ends = [0, len(means) - 1]
    ax.errorbar(
        ends,
        means[ends],
        yerr=SIGMAS * np.sqrt(covs[ends]),
        fmt="none",
        ecolor="tab:red",
        capsize=4,
        label="3σ",
    )
    ax.set_xlabel("step k")
    ax.set_ylabel(name)
    ax.set_title(f"{headline(result)}\n{name} against the step", fontsize="medium")
    ax.legend(**LEGEND_RIGHT)


def plot(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """Write the plots of an LQ stochastic game Result into ``output_dir``; return their paths."""
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    if "mean" not in result.arrays:
        return written
    figures = [("first_state.png", _first_state)]
    if result.arrays["mean"].shape[1] >= 2:
        figures.insert(0, ("ellipses.png", _plane))
    for name, draw in figures:
        fig, ax = plt.subplots(figsize=(8, 5))
        draw(ax, result)
        if draw is _plane:
            _inset(ax, result)
        fig.savefig(output_dir / name, dpi=120, bbox_inches="tight")
        plt.close(fig)
        written.append(output_dir / name)
    history = result.arrays.get("convergence_history")
    if history is not None and len(history):
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.semilogy(np.arange(1, len(history) + 1), history[:, 0], "o-", label="ε_k")
        ax.semilogy(np.arange(1, len(history) + 1), history[:, 1], "s-", label="ε_ℓ")
        ax.set_xlabel("Jacobi iteration")
        ax.set_ylabel("change of the gains")
        ax.set_title(f"{headline(result)}\nAlgorithm 2 convergence", fontsize="medium")
        ax.legend(**LEGEND_RIGHT)
        fig.savefig(output_dir / "convergence.png", dpi=120, bbox_inches="tight")
        plt.close(fig)
        written.append(output_dir / "convergence.png")
    if animate and result.arrays["mean"].shape[1] >= 2:
        fig, ax = plt.subplots(figsize=(8.5, 5))
        fig.subplots_adjust(left=0.1, right=0.7, top=0.85)
        _plane(ax, result)
        limits = ax.get_xlim(), ax.get_ylim()

        def frame(k: int) -> None:
            ax.clear()
            _plane(ax, result, upto=k)
            ax.set(xlim=limits[0], ylim=limits[1])

        anim = FuncAnimation(fig, frame, frames=len(result.arrays["mean"]))
        anim.save(output_dir / "ellipses.gif", writer=PillowWriter(fps=4))
        plt.close(fig)
        written.append(output_dir / "ellipses.gif")
    return written
