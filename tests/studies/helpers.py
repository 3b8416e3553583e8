"""Module-level task functions for the executor tests (picklable by reference in any worker)."""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path


def square(x: int) -> int:
    return x * x


def slow_square(x: int) -> int:
    time.sleep(0.25)
    return x * x


def announce_and_sleep(seconds: float) -> int:
    """Print this worker's PID on stdout (the worker is past its initializer), then sleep."""
    sys.stdout.write(f"{os.getpid()}\n")  # one write: two workers share the pipe
    sys.stdout.flush()
    time.sleep(seconds)
    return os.getpid()


def square_or_die_once(job: tuple[int, str]) -> int:
    """``x²``, except that the first worker to meet ``x == 3`` kills itself by its own PID (the
    marker file makes the retry succeed)."""
    x, marker = job
    if x == 3 and not Path(marker).exists():
        Path(marker).touch()
        os.kill(os.getpid(), signal.SIGKILL)
    return x * x


def mean_of_squares(batch: dict) -> dict:
    """A Monte Carlo batch function: per draw, x² and the row sum of v."""
    return {"sq": batch["x"] ** 2, "total": batch["v"].sum(axis=1)}
