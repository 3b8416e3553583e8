"""The time limit and the progress line of a flow-field reachability run (issue 27: what may take
long shows progress and stops at its limit with the status ``time_limit``).

A :class:`Budget` is handed to the marching loops (level sets, extremal shooting); each asks
:meth:`Budget.expired` once per step and reports the time reached with :meth:`Budget.advance`
(a live bar on a terminal, a plain line every few seconds elsewhere, nothing with ``--quiet``:
:mod:`gamespec.terminal`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

from gamespec.terminal import Tracker


@dataclass(frozen=True)
class Budget:
    """``max_wall_time`` seconds from ``started`` (None: no limit) and where progress goes."""

    max_wall_time: float | None = None
    tracker: Tracker | None = None
    started: float = field(default_factory=time.perf_counter)

    def expired(self) -> bool:
        """Whether the limit has passed."""
        return self.max_wall_time is not None and time.perf_counter() - self.started > self.max_wall_time

    def advance(self, info: str) -> None:
        """Count one step done, with ``info`` (the time reached) shown next to the count."""
        if self.tracker is not None:
            self.tracker.advance(info=info)

    def message(self, what: str) -> str:
        """Why a run stopped at the limit: ``what`` it had reached."""
        return f"time limit of {self.max_wall_time:g} s (max_wall_time) reached: {what}"


UNLIMITED = Budget()
"""No limit and no progress (tests, benchmarks, cross-checks inside a limited run use their own)."""
