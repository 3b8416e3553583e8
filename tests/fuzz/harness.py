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
"""CPU seconds one input may take (CPU time, not wall time: a loaded shared machine does not make
an input look hung; a hang is unbounded)."""

EXIT_CODES: Counter[int] = Counter()
"""Exit codes of every input run in this session (printed in the pytest summary)."""


class Hang(BaseException):
    """An input ran past :data:`TIME_BOUND_S` (a BaseException, so no ``except Exception`` in the
    code under test swallows it)."""


@dataclass(frozen=True)
class Outcome:
    """What one CLI run gave."""

    code: int
    out: str
    err: str
    seconds: float


@contextlib.contextmanager
def _time_bound(seconds: float) -> Iterator[None]:
    """Raise :class:`Hang` once this process has used ``seconds`` of CPU time (``ITIMER_PROF``)."""

    def expire(signum: int, frame: object) -> None:
        raise Hang(f"no answer within {seconds} s")

    previous = signal.signal(signal.SIGPROF, expire)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, previous)


def run_cli(args: Sequence[str], bound_s: float = TIME_BOUND_S) -> Outcome:
    """``gamespec ARGS`` in this process with stdout and stderr captured, within ``bound_s``."""
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
