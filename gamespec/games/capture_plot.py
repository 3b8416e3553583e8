"""The figure of a ``differential_game`` Result that holds a value function (the ``hji`` backend):
the captured set ``φ ≤ 0`` filled, the zero contour of the value and the grid's box."""

from __future__ import annotations

from pathlib import Path

from gamespec.plotting import LEGEND_RIGHT, headline
from gamespec.result import Result


def plot_capture_region(result: Result, output_dir: Path) -> list[Path]:
    """``capture_region.png`` in ``output_dir``; its path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    value, x, y = result.arrays["value"], result.arrays["grid_x"], result.arrays["grid_y"]
    region = result.metrics["capture_region"]
    output_dir.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 6))
    ax.contourf(x, y, value.T, levels=[value.min() - 1, 0.0], colors=["tab:red"], alpha=0.35)
    ax.contour(x, y, value.T, levels=[0.0], colors=["tab:red"])
    ax.plot([], [], color="tab:red", label=f"captured within T = {region['horizon']:g}")
    ax.set_xlabel(region["states"][0])
    ax.set_ylabel(region["states"][1])
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(y[0], y[-1])
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.legend(**LEGEND_RIGHT)
    ax.set_title(f"{headline(result)}\ncaptured area {region['area']:.4g}", fontsize="medium")
    path = output_dir / "capture_region.png"
    fig.savefig(path, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return [path]
