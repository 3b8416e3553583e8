"""Run the CLI in-process on one input under a time bound and check the bad-input promise.

The promise (README, "Bad input"): exit 0; or exit 1 with one line on stderr giving the Result's
status; or exit 2 with one line on stderr, ``error: <file or --set>: [<field>: ]<reason>``, and
nothing else on stderr. An exception escaping :func:`gamespec.cli.run` is a bug and fails the test
with its traceback; an input that runs past the bound fails it as a hang.
"""

from __future__ import annotations

import contextlib
import io
import os
import signal
import time
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

TIME_BOUND_S = float(os.environ.get("GAMESPEC_FUZZ_TIME_BOUND_S", "5"))
"""CPU seconds one input may take (process CPU time, all threads: a loaded machine slows an input
down without making it a hang)."""

BLOCKED_BOUND_S = float(os.environ.get("GAMESPEC_FUZZ_BLOCKED_BOUND_S", "120"))
"""Wall-clock seconds after which an input is a hang even without using CPU (a read that blocks on
a FIFO uses none); far above what a loaded machine needs for :data:`TIME_BOUND_S` of CPU."""

EXIT_CODES: Counter[int] = Counter()
"""Exit codes of every input run in this session (printed in the pytest summary)."""


class Hang(BaseException):
    """An input ran past :data:`TIME_BOUND_S` of CPU time, or blocked past
    :data:`BLOCKED_BOUND_S` (a BaseException, so no ``except Exception`` in the code under test
    swallows it)."""


@dataclass(frozen=True)
class Outcome:
    """What one CLI run gave."""

    code: int
    out: str
    err: str
    seconds: float


@contextlib.contextmanager
def _time_bound(seconds: float, blocked: float = BLOCKED_BOUND_S) -> Iterator[None]:
    """Raise :class:`Hang` after ``seconds`` of this process's CPU time (``ITIMER_PROF``) or
    ``blocked`` seconds of wall-clock time, whichever comes first."""

    def expire(signum: int, frame: object) -> None:
        what = f"{seconds} s of CPU time" if signum == signal.SIGPROF else f"{blocked} s (blocked)"
        raise Hang(f"no answer within {what}")

    previous = {sig: signal.signal(sig, expire) for sig in (signal.SIGPROF, signal.SIGALRM)}
    signal.setitimer(signal.ITIMER_PROF, seconds)
    signal.setitimer(signal.ITIMER_REAL, blocked)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.setitimer(signal.ITIMER_REAL, 0)
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def run_cli(args: Sequence[str], bound_s: float = TIME_BOUND_S) -> Outcome:
    """``gamespec ARGS`` in this process with stdout and stderr captured, within ``bound_s`` of CPU
    time (:func:`_time_bound`)."""
    from gamespec.cli import run

    out, err = io.StringIO(), io.StringIO()
    start = time.perf_counter()
    try:
        with _time_bound(bound_s), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = run([str(a) for a in args])
    except Hang as hang:
        raise Hang(f"{hang}: gamespec {' '.join(map(str, args))}") from None
    EXIT_CODES[code] += 1
    return Outcome(code, out.getvalue(), err.getvalue(), time.perf_counter() - start)


def assert_promise(outcome: Outcome, *sources: str) -> None:
    """The bad-input promise for one outcome; ``sources`` are the names an exit-2 line may start
    with (the file, ``--set``)."""
    lines = outcome.err.strip().splitlines()
    assert outcome.code in (0, 1, 2), outcome
    if outcome.code == 0:
        assert outcome.err == "", outcome
        return
    assert len(lines) == 1, outcome
    line = lines[0]
    assert "Traceback" not in line, outcome
    if outcome.code == 1:
        assert "status" in line, outcome
        return
    assert line.startswith("error: "), outcome
    assert any(line.startswith(f"error: {s}") for s in sources), (sources, outcome)
    assert len(line.removeprefix("error: ").split(": ", 1)) == 2, outcome


def check(args: Sequence[str], *sources: str) -> Outcome:
    """Run and assert the promise; the outcome, for further checks."""
    outcome = run_cli(args)
    assert_promise(outcome, *sources)
    return outcome
