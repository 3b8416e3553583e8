"""What a person sees on the terminal: consoles that do not wrap off a terminal, and progress.

On a terminal, rich draws tables to the window's width and long runs show a live progress bar on
stderr. Off a terminal (a pipe, a file, a CI log) nothing is live: tables and one-line messages are
written at their full width, never broken at 80 columns in the middle of a path, and a long run
prints a short plain progress line to stderr every :data:`PROGRESS_PERIOD_S` seconds, so that a run
of many minutes still shows that it is alive. :func:`set_quiet` (``gamespec --quiet``) silences
progress everywhere; results and errors are still printed.

rich is imported only when something is printed.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cache
from typing import TYPE_CHECKING, TextIO

if TYPE_CHECKING:
    from rich.console import Console
    from rich.progress import Progress

PROGRESS_PERIOD_S = 5.0
"""Seconds between two plain progress lines off a terminal."""

UNWRAPPED_WIDTH = 10_000
"""The console width off a terminal: wide enough that no table or message of gamespec wraps."""

_settings = {"quiet": False}


def set_quiet(quiet: bool) -> None:
    """Silence (or restore) progress output for the rest of the process."""
    _settings["quiet"] = quiet


def quiet() -> bool:
    """Whether progress output is silenced."""
    return _settings["quiet"]


def _stream(stderr: bool) -> TextIO:
    return sys.stderr if stderr else sys.stdout


@cache
def console(stderr: bool = False) -> Console:
    """rich's console on stdout (or stderr): the window's width on a terminal, unwrapped elsewhere."""
    from rich.console import Console

    if _stream(stderr).isatty():
        return Console(stderr=stderr)
    return Console(stderr=stderr, width=UNWRAPPED_WIDTH, soft_wrap=True)


@dataclass
class Tracker:
    """The progress of one long run: :meth:`advance` after each unit of work, with an optional
    ``info`` text (the current iterate, a residual) shown next to the count."""

    description: str
    total: int | None
    completed: int = 0
    _bar: Progress | None = None
    _task: int | None = None
    _stream: TextIO | None = None
    _started: float = field(default_factory=time.monotonic)
    _last_line: float = field(default_factory=time.monotonic)

    def advance(self, count: int = 1, info: str = "") -> None:
        """Count ``count`` more units done."""
        self.completed += count
        if self._bar is not None and self._task is not None:
            self._bar.update(self._task, advance=count, info=info)
        elif self._stream is not None and time.monotonic() - self._last_line >= PROGRESS_PERIOD_S:
            self._print_line(info)

    def _print_line(self, info: str) -> None:
        self._last_line = time.monotonic()
        of = f"/{self.total}" if self.total is not None else ""
        tail = f", {info}" if info else ""
        elapsed = self._last_line - self._started
        line = f"{self.description}: {self.completed}{of} after {elapsed:.0f} s{tail}"
        print(line, file=self._stream, flush=True)


@contextmanager
def progress(description: str, total: int | None = None, enabled: bool = True) -> Iterator[Tracker]:
    """Report the progress of a long run on stderr (see the module doc): a transient rich bar on a
    terminal, a plain line every few seconds elsewhere, nothing when quiet or not ``enabled``."""
    tracker = Tracker(description, total)
    if not enabled or quiet():
        yield tracker
        return
    if not sys.stderr.isatty():
        tracker._stream = sys.stderr
        yield tracker
        return
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    bar = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
        TextColumn("{task.fields[info]}"),
        console=console(stderr=True),
        transient=True,
    )
    with bar:
        tracker._bar = bar
        tracker._task = bar.add_task(description, total=total, info="")
        yield tracker
