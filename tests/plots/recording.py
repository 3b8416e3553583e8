"""Record the figures a plotter saves (at a low resolution, for speed) and read what they show."""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

from matplotlib.axes import Axes
from matplotlib.figure import Figure


@dataclass
class Saved:
    """One saved figure: its file name and what it shows."""

    name: str
    figure: Figure
    title: str
    axes: list[Axes] = field(default_factory=list)
    legend_outside: list[bool | None] = field(default_factory=list)
    """Per axes: whether its legend lies outside the axes (covers none of the data); None: no legend."""


@contextmanager
def recording(dpi: int = 30):
    """Within the block, every ``Figure.savefig`` to a file is recorded (figures are drawn at ``dpi``)."""
    saved: list[Saved] = []
    original = Figure.savefig

    def record(self: Figure, fname, *args, **kwargs):
        if not isinstance(fname, str | Path):
            return original(self, fname, *args, **kwargs)
        kwargs["dpi"] = dpi
        out = original(self, fname, *args, **kwargs)
        title = self._suptitle.get_text() if self._suptitle is not None else ""
        outside = [_legend_outside(ax) if ax.get_legend() is not None else None for ax in self.axes]
        saved.append(Saved(Path(fname).name, self, title, list(self.axes), outside))
        return out

    Figure.savefig = record
    try:
        yield saved
    finally:
        Figure.savefig = original


def titles(saved: Saved) -> str:
    """The suptitle and every axes' title, joined."""
    return " ".join([saved.title, *(ax.get_title() for ax in saved.axes)])


def _legend_outside(ax: Axes) -> bool:
    renderer = ax.figure.canvas.get_renderer()
    return not ax.get_legend().get_window_extent(renderer).overlaps(ax.get_window_extent(renderer))


def legend_texts(ax: Axes) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]
