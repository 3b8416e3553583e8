"""Plots of an ``lq_stochastic_game`` Result (registered as that kind's plotter).

- ``ellipses.png``: the first two states' plane with the sampled closed-loop trajectories (gray),
  the mean (blue) and its 3σ ellipses, and the initial and target 3σ ellipses (red), as in
  Figs. 4.1–4.3;
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

from gamespec.result import Result

SIGMAS = 3.0


def ellipse_points(mean: np.ndarray, covariance: np.ndarray, sigmas: float = SIGMAS) -> np.ndarray:
    """Points (64, 2) on the ``sigmas``-σ ellipse of a 2-D Gaussian."""
    values, vectors = np.linalg.eigh(covariance)
    angle = np.linspace(0, 2 * np.pi, 64)
    circle = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    return mean + sigmas * circle * np.sqrt(np.maximum(values, 0)) @ vectors.T


def _plane(ax: Axes, result: Result, upto: int | None = None) -> None:
    names = list(result.states)
    means, covs = result.arrays["mean"], result.arrays["covariance"]
    last = len(means) if upto is None else upto + 1
    if "samples" in result.arrays:
        for path in result.arrays["samples"][:, :last, :2]:
            ax.plot(path[:, 0], path[:, 1], color="0.75", lw=0.6)
    ax.plot(means[:last, 0], means[:last, 1], color="tab:blue", lw=1.5, label="mean")
    for k in range(last):
        ax.plot(*ellipse_points(means[k, :2], covs[k, :2, :2]).T, color="tab:blue", lw=0.8)
    ax.plot(
        *ellipse_points(means[0, :2], covs[0, :2, :2]).T, color="tab:red", lw=1.2, label="initial / target"
    )
    if "target_covariance" in result.arrays:
        target = result.arrays.get("target_mean", means[-1])
        centre = np.where(np.isnan(target[:2]), means[-1, :2], target[:2])
        ax.plot(
            *ellipse_points(centre, result.arrays["target_covariance"][:2, :2]).T, color="tab:red", lw=1.2
        )
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1])
    ax.set_title(f"{result.problem}: {result.status.value}, 3σ ellipses")
    ax.legend(loc="best", fontsize=8)


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
    ax.set_title(f"{result.problem}: {name} against the step")
    ax.legend(loc="best", fontsize=8)


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
        fig, ax = plt.subplots(figsize=(6, 4.5))
        draw(ax, result)
        fig.tight_layout()
        fig.savefig(output_dir / name, dpi=120)
        plt.close(fig)
        written.append(output_dir / name)
    history = result.arrays.get("convergence_history")
    if history is not None and len(history):
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.semilogy(np.arange(1, len(history) + 1), history[:, 0], "o-", label="ε_k")
        ax.semilogy(np.arange(1, len(history) + 1), history[:, 1], "s-", label="ε_ℓ")
        ax.set_xlabel("Jacobi iteration")
        ax.set_title("Algorithm 2 convergence")
        ax.legend()
        fig.tight_layout()
        fig.savefig(output_dir / "convergence.png", dpi=120)
        plt.close(fig)
        written.append(output_dir / "convergence.png")
    if animate and result.arrays["mean"].shape[1] >= 2:
        fig, ax = plt.subplots(figsize=(6, 4.5))

        def frame(k: int) -> None:
            ax.clear()
            _plane(ax, result, upto=k)

        anim = FuncAnimation(fig, frame, frames=len(result.arrays["mean"]))
        anim.save(output_dir / "ellipses.gif", writer=PillowWriter(fps=4))
        plt.close(fig)
        written.append(output_dir / "ellipses.gif")
    return written
