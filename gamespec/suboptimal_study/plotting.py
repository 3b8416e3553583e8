"""Plot of a ``pursuit_suboptimal_study`` Result: its table (Table 2.1 of §2.4.4 for the shipped
file) as a figure, titled by the study's name.

Read from the Result only: the per-point percentage variation (``arrays``) and the per-speed
average and maximum (``metrics["table"]``).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from gamespec.plotting import LEGEND_RIGHT
from gamespec.result import Result


def plot_study(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """``variation.png``: 100 (t_opt − t_sub)/t_opt per solved point against v, with the average
    and maximum per speed (the rows of the study's table). There is nothing to animate."""
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    v, variation = result.arrays["v"], result.arrays["variation_percent"]
    solved = np.isfinite(variation)
    table = result.metrics["table"]
    speeds = [row["v"] for row in table]
    average, maximum = (
        np.array([row[f"{stat}_variation_percent"] for row in table], dtype=float)
        for stat in ("average", "maximum")
    )
    fig, ax = plt.subplots(figsize=(7.5, 4))
    ax.scatter(v[solved], variation[solved], s=8, alpha=0.4, label=f"points ({int(solved.sum())} solved)")
    ax.plot(speeds, average, "o-", label="average per speed")
    ax.plot(speeds, maximum, "s--", label="maximum per speed")
    ax.set(xlabel="evader speed v", ylabel="100 (t_opt − t_sub)/t_opt  [%]")
    worst = float(np.nanmax(maximum)) if np.isfinite(maximum).any() else float("nan")
    ax.set_title(
        f"{result.problem} — {result.backend}, {result.status.value}: suboptimal heading (eq. 2.27) "
        f"against the optimum\nlargest variation {worst:.3g} %",
        fontsize="medium",
    )
    ax.legend(**LEGEND_RIGHT)
    path = output_dir / "variation.png"
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return [path]
