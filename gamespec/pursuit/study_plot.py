"""Plot of a ``pursuit_suboptimal_study`` Result: Table 2.1 (§2.4.4) as a figure.

Read from the Result only: the per-point percentage variation (``arrays``) and the per-speed
average and maximum (``metrics["table"]``).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from gamespec.result import Result


def plot_study(result: Result, output_dir: Path, *, animate: bool = False) -> list[Path]:
    """``table_2_1.png``: 100 (t_opt − t_sub)/t_opt per solved point against v, with the average
    and maximum per speed (Table 2.1). There is nothing to animate."""
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
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.scatter(v[solved], variation[solved], s=8, alpha=0.4, label="points")
    ax.plot(speeds, average, "o-", label="average")
    ax.plot(speeds, maximum, "s--", label="maximum")
    ax.set(xlabel="evader speed v", ylabel="100 (t_opt − t_sub)/t_opt  [%]", title="Table 2.1")
    ax.legend()
    path = output_dir / "table_2_1.png"
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return [path]
