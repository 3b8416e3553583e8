"""Figures of desensitized Results (chapter 6): the nominal path with the Monte Carlo bundle
(Figs. 6.1(c), 6.2(a), 6.4), the sensitivity trajectories S(t) (Fig. 6.1(b)), and the trade-off of
the original cost against the sensitivity measure across a sweep of the weight (Fig. 6.3(b)).
Plots read Results (or the rows a sweep saved) only.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from gamespec.errors import GamespecError
from gamespec.plotting import LEGEND_RIGHT, headline, is_flat
from gamespec.result import Result

SENSITIVITY_PREFIXES = ("S_", "mu_", "Phi_")


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _original_states(result: Result) -> list[str]:
    return list(result.metrics["monte_carlo"]["final_state_mean"]) if "monte_carlo" in result.metrics else []


def plot_desensitized(result: Result, output_dir: Path) -> list[Path]:
    """The Monte Carlo bundle about the nominal path, and the sensitivity trajectories."""
    plt = _pyplot()
    output_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    states = _original_states(result)
    if states:
        declared = result.metrics.get("plot", {}).get("planar", [])
        planar = declared[0] if declared and set(declared[0]) <= set(states) else None
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        for prefix, color, label in (
            ("monte_carlo", "0.6", "open loop"),
            ("tracking", "tab:green", "LQR tracking"),
        ):
            if f"{prefix}_{states[0]}" not in result.arrays:
                continue
            xs = (
                result.arrays[f"{prefix}_{planar[0]}"]
                if planar
                else result.arrays["monte_carlo_time"][:, None]
            )
            ys = result.arrays[f"{prefix}_{planar[1] if planar else states[0]}"]
            lines = ax.plot(xs if planar else xs.repeat(ys.shape[1], 1), ys, color=color, lw=0.6, alpha=0.5)
            note = f"{label} ({result.metrics['monte_carlo']['samples']} samples, first {ys.shape[1]})"
            if _coincide(ys, xs if planar else None):
                uncertain = (
                    ", ".join(result.metrics["monte_carlo"].get("parameters", {})) or "the uncertainty"
                )
                note += f"\nall on one path: {uncertain} does not move these states"
            lines[0].set_label(note)
        x_nominal = result.states[planar[0]] if planar else result.time
        ax.plot(x_nominal, result.states[planar[1] if planar else states[0]], "k-", lw=2, label="nominal")
        ax.set_xlabel(planar[0] if planar else "t")
        ax.set_ylabel(planar[1] if planar else states[0])
        ax.grid(alpha=0.3)
        ax.legend(**LEGEND_RIGHT)
        ax.set_title(
            f"{headline(result)}\nMonte Carlo about the nominal{collision_note(result)}", fontsize="medium"
        )
        paths.append(output_dir / f"{result.problem}_monte_carlo.png")
        fig.savefig(paths[-1], dpi=120, bbox_inches="tight")
        plt.close(fig)
    curves = {k: v for k, v in result.states.items() if k.startswith(SENSITIVITY_PREFIXES)}
    if curves:
        fig, ax = plt.subplots(figsize=(6.5, 4))
        for name, values in curves.items():
            ax.plot(result.time, values, label=name)
        ax.set_xlabel("t")
        ax.set_ylabel("sensitivity")
        ax.grid(alpha=0.3)
        ax.legend(**LEGEND_RIGHT)
        method = result.metrics["desensitization"]["method"]
        ax.set_title(f"{headline(result)}\nsensitivities ({method})", fontsize="medium")
        paths.append(output_dir / f"{result.problem}_sensitivity.png")
        fig.savefig(paths[-1], dpi=120, bbox_inches="tight")
        plt.close(fig)
    return paths


def _coincide(ys, xs) -> bool:
    """Whether every sampled path is the same (to :data:`~gamespec.plotting.FLAT_TOLERANCE`) at
    every time: an uncertainty that does not enter the drawn states."""
    bundles = [ys] if xs is None else [ys, xs]
    return all(all(is_flat(row) for row in np.asarray(b, dtype=float)) for b in bundles)


def collision_note(result: Result) -> str:
    """``, P_c = p [low, high]`` (the open-loop Monte Carlo's collision probability and its
    interval) where the Result has one."""
    mc = result.metrics.get("monte_carlo", {})
    if "collision_probability" not in mc:
        return ""
    low, high = (0.0 if abs(v) < 1e-12 else v for v in mc["collision_probability_ci"])
    return f", collision probability P_c = {mc['collision_probability']:.3g} [{low:.2g}, {high:.2g}]"


def desensitized_rows(values: Iterable[Mapping[str, Any]]) -> list[Mapping[str, Any]]:
    """The rows of a sweep (its points' saved values, validated: :mod:`gamespec.studies.rows`)
    whose metrics carry both the original cost and the sensitivity measure."""
    keys = ("nominal_objective", "sensitivity_measure")
    return [v for v in values if all(isinstance(v.get("metrics", {}).get(k), int | float) for k in keys)]


def plot_tradeoff(values: Iterable[Mapping[str, Any]], output_dir: Path, parameter: str) -> list[Path]:
    """Original cost against the sensitivity measure, one point per value of the swept
    ``parameter`` (Fig. 6.3(b)), from a sweep's validated rows."""
    rows = desensitized_rows(values)
    if not rows:
        raise GamespecError("the sweep holds no solved desensitized points to plot")
    plt = _pyplot()
    name = parameter
    rows.sort(key=lambda r: r.get(name, 0.0))
    cost = [r["metrics"]["nominal_objective"] for r in rows]
    measure = [r["metrics"]["sensitivity_measure"] for r in rows]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(measure, cost, "o-")
    for r, x, y in zip(rows, measure, cost, strict=True):
        ax.annotate(
            f"{name}={r.get(name, float('nan')):g}",
            (x, y),
            textcoords="offset points",
            xytext=(5, 5),
            fontsize=8,
        )
    ax.set_xlabel("sensitivity measure")
    ax.set_ylabel("original cost")
    ax.grid(alpha=0.3)
    ax.set_title(f"{rows[0].get('problem', '')}: cost against sensitivity")
    fig.tight_layout()
    path = output_dir / "tradeoff.png"
    output_dir.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return [path]
