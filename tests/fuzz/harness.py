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

IDLE_WINDOW_S = float(os.environ.get("GAMESPEC_FUZZ_IDLE_WINDOW_S", "10"))
"""Wall-clock seconds over which an input that used less than :data:`IDLE_SHARE` of them in CPU
time counts as blocked (a read that blocks on a FIFO uses none). A loaded machine slows an input
down but leaves it running: it keeps using CPU, so load never reads as blocked."""

IDLE_SHARE = 0.01
"""The share of a window's wall time below which an input's CPU use means it is blocked."""

EXIT_CODES: Counter[int] = Counter()
"""Exit codes of every input run in this session (printed in the pytest summary)."""


class Hang(BaseException):
    """An input ran past its CPU-time bound, or blocked for an idle window (a BaseException, so no
    ``except Exception`` in the code under test swallows it)."""


@dataclass(frozen=True)
class Outcome:
    """What one CLI run gave; ``seconds`` is the CPU time it took (this process, all threads)."""

    code: int
    out: str
    err: str
    seconds: float


@contextlib.contextmanager
def cpu_bound(seconds: float, idle_window: float = IDLE_WINDOW_S) -> Iterator[None]:
    """Raise :class:`Hang` after ``seconds`` of this process's CPU time (``ITIMER_PROF``), or at the
    end of any ``idle_window`` of wall-clock time in which the process used less than
    :data:`IDLE_SHARE` of it in CPU time (blocked: no CPU bound can see it). Both are judged by CPU
    time, so neither fires on a loaded machine. A bound that fired inside code that swallowed the
    exception (CasADi turns an exception in IPOPT's callback into a warning and carries on) is
    raised when the body returns."""
    used = [time.process_time()]
    fired: list[str] = []

    def out_of_cpu(signum: int, frame: object) -> None:
        fired.append(f"no answer within {seconds} s of CPU time")
        raise Hang(fired[-1])

    def idle(signum: int, frame: object) -> None:
        now = time.process_time()
        if now - used[0] < IDLE_SHARE * idle_window:
            fired.append(f"blocked: {now - used[0]:.3f} s of CPU time in {idle_window} s")
            raise Hang(fired[-1])
        used[0] = now

    previous = {sig: signal.getsignal(sig) for sig in (signal.SIGPROF, signal.SIGALRM)}
    signal.signal(signal.SIGPROF, out_of_cpu)
    signal.signal(signal.SIGALRM, idle)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    signal.setitimer(signal.ITIMER_REAL, idle_window, idle_window)
    try:
        yield
        if fired:
            raise Hang(f"{fired[0]} (the code under test caught it and went on)")
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.setitimer(signal.ITIMER_REAL, 0)
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def run_cli(args: Sequence[str], bound_s: float = TIME_BOUND_S) -> Outcome:
    """``gamespec ARGS`` in this process with stdout and stderr captured, within ``bound_s`` of CPU
    time and never blocked (:func:`cpu_bound`)."""
    from gamespec.cli import run

    out, err = io.StringIO(), io.StringIO()
    start = time.process_time()
    try:
        with cpu_bound(bound_s), contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = run([str(a) for a in args])
    except Hang as hang:
        raise Hang(f"{hang}: gamespec {' '.join(map(str, args))}") from None
    EXIT_CODES[code] += 1
    return Outcome(code, out.getvalue(), err.getvalue(), time.process_time() - start)


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
