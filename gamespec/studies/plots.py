"""Figures of a study folder (``gamespec plot DIR`` on a sweep's or compare's ``--out``).

- a sweep: ``sweep_<parameter>.png`` per swept parameter, each output (objective, t_f, and the
  capture times of a Table 2.1 study) against it, one line per combination of the other parameters;
  ``tradeoff.png`` (Fig. 6.3(b)) when its points are desensitized Results; and
  ``capture_probability_<parameter>.png`` (Fig. 5.2) when they are flow-field games;
- a compare: ``compare.png``, bars per backend of the objective and the solve time.

Read from the store only (:mod:`gamespec.studies.export`), never from solver objects.
"""

from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from gamespec.desensitize.plotting import desensitized_rows, plot_tradeoff
from gamespec.errors import GamespecError
from gamespec.flowfield.plotting import capture_rows, plot_capture_sweep
from gamespec.studies.export import study_rows
from gamespec.studies.rows import study_meta, valid_points
from gamespec.studies.store import ResultStore

OUTPUTS = ("objective", "t_final", "t_optimal", "t_suboptimal")
"""Row fields drawn against each swept parameter, where the rows have them."""

MAX_LEGEND = 8


def _number(value: Any) -> float | None:
    ok = isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)
    return float(value) if ok else None


def _sweep(rows: list[dict[str, Any]], parameters: list[str], folder: Path) -> list[Path]:
    outputs = [c for c in OUTPUTS if any(_number(r.get(c)) is not None for r in rows)]
    if not outputs:
        raise GamespecError(f"{folder}: the points have none of {', '.join(OUTPUTS)} to plot")
    paths = []
    for name in parameters:
        others = [p for p in parameters if p != name]
        groups: dict[tuple, list[dict[str, Any]]] = defaultdict(list)
        for row in rows:
            groups[tuple(row.get(p) for p in others)].append(row)
        fig, axes = plt.subplots(len(outputs), 1, figsize=(6, 2.6 * len(outputs)), sharex=True, squeeze=False)
        for ax, output in zip(axes[:, 0], outputs, strict=True):
            for label, members in sorted(groups.items(), key=lambda item: str(item[0])):
                pts = sorted(
                    (x, y)
                    for r in members
                    if (x := _number(r.get(name))) is not None and (y := _number(r.get(output))) is not None
                )
                if pts:
                    tag = ", ".join(f"{p}={v:.4g}" for p, v in zip(others, label, strict=True))
                    ax.plot(*zip(*pts, strict=True), "o-", ms=3, label=tag or None)
            ax.set_ylabel(output)
            if others and len(groups) <= MAX_LEGEND:
                ax.legend(fontsize="small")
        axes[-1, 0].set_xlabel(name)
        fig.suptitle(f"sweep over {name}")
        path = folder / f"sweep_{name}.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        plt.close(fig)
        paths.append(path)
    return paths


def _compare(rows: list[dict[str, Any]], folder: Path) -> list[Path]:
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
    labels = [str(r.get("backend", r["key"])) for r in rows]
    panels = (("objective", "objective"), ("solve_time_s", "solve time [s]"))
    for ax, (field, title) in zip(axes, panels, strict=True):
        heights = [_number(r.get(field)) for r in rows]
        colours = ["tab:green" if r.get("status") == "optimal" else "tab:orange" for r in rows]
        ax.bar(labels, [h if h is not None else 0.0 for h in heights], color=colours)
        ax.set_title(title)
        ax.tick_params(axis="x", rotation=30)
    fig.suptitle("backend comparison (green: optimal)")
    path = folder / "compare.png"
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return [path]


def plot_study(store: ResultStore, output_dir: str | Path) -> list[Path]:
    """The figures of the study in ``store`` (see module doc), written into ``output_dir``."""
    folder = Path(output_dir)
    study = study_meta(store)
    rows = study_rows(store)
    if not rows:
        raise GamespecError(f"{store.folder}: the study has no valid points yet")
    if study.type == "compare":
        return _compare(rows, folder)
    if study.type == "sweep":
        paths = _sweep(rows, study.parameters, folder)
        values = list(valid_points(store).values())
        if desensitized_rows(values) and study.parameters:
            paths += plot_tradeoff(values, folder, study.parameters[0])
        games = capture_rows(values)
        for name in study.parameters if games else []:
            points = [(row[name], row["metrics"]) for row in games if _number(row.get(name)) is not None]
            figure = folder / f"capture_probability_{name}.png"
            paths.append(plot_capture_sweep(points, name, figure, study.problem))
        return paths
    damaged = [line for line in store.damaged if "meta:study" in line]
    why = f" ({damaged[0].split(': ', 1)[1]})" if damaged else ""
    raise GamespecError(f"{store.folder}: not a sweep or a compare study{why}")
