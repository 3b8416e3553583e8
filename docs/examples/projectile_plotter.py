"""A new plotter: the flight of a ``projectile`` Result. A plotter reads the Result only and
returns the paths it wrote; it is the ``plot`` of the kind's :class:`~gamespec.registry.Kind`, so
``gamespec plot`` and ``gamespec solve --plot`` call it by kind (an installed package names it in
its one ``Kind``: ``plot="gamespec_projectile.plotter:plot_projectile"``)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from gamespec import registry
from gamespec.plotting import LEGEND_RIGHT, headline
from gamespec.result import Result


def plot_projectile(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """``flight.png``: height against distance, the landing point marked."""
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    x, y = result.states["x"], result.states["y"]
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(x, y, label="flight")
    ax.plot(x[-1], y[-1], "kx", label=f"landing, range {result.metrics['range']:.4g}")
    ax.set(xlabel="x [m]", ylabel="y [m]", title=headline(result))
    ax.legend(**LEGEND_RIGHT)
    path = output_dir / "flight.png"
    fig.savefig(path, dpi=100, bbox_inches="tight")
    plt.close(fig)
    return [path]


registry.register("gamespec.kinds", "projectile", replace(registry.kind("projectile"), plot=plot_projectile))
