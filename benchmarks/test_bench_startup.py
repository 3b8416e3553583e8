"""Start-up (issue 16, item 2): the CPU time (user + system, of the child process) of
``gamespec --help``, ``gamespec validate`` and ``gamespec solve`` on
``problems/ch6/zermelo_min_time.yaml``, against a plain Python script that solves the same NLP with
CasADi (:mod:`benchmarks.plain_zermelo_min_time`), each a fresh interpreter, measured interleaved in
the same run (median of ``ROUNDS``).

Goals (asserted): ``solve`` ≤ 2× the plain script; ``--help`` and ``validate`` under 0.5 s of CPU.
The ratios and times go to the benchmark's ``extra_info`` and to the terminal.

Bytecode: a user's install has it (pip compiles an installed package; an editable install writes
``__pycache__`` on its first import), so the project's own packages (``gamespec``, ``backends``,
``benchmarks``) are byte-compiled once before the rounds (:func:`compile_project`). Without it, an
environment that sets ``PYTHONDONTWRITEBYTECODE`` (as CI machines do) would compile every project
module from source in every child, on both sides of the ratio.

Run: ``python -m pytest benchmarks/test_bench_startup.py --benchmark-enable -s``.
"""

from __future__ import annotations

import compileall
import json
import resource
import statistics
import subprocess
import sys

import pytest

from tests.conftest import PROBLEMS

ROOT = PROBLEMS.parent
FILE = str(PROBLEMS / "ch6" / "zermelo_min_time.yaml")
GAMESPEC = [sys.executable, "-c", "from gamespec.cli import main; main()"]
"""What the ``gamespec`` console script runs."""
COMMANDS = {
    "plain_casadi": [sys.executable, "-m", "benchmarks.plain_zermelo_min_time"],
    "help": [*GAMESPEC, "--help"],
    "validate": [*GAMESPEC, "validate", FILE],
    "solve": [*GAMESPEC, "solve", FILE, "--json"],
}
ROUNDS = 3
PACKAGES = ("gamespec", "backends", "benchmarks")
"""The project's own source trees, byte-compiled before the rounds (site-packages already is)."""


def compile_project() -> None:
    """Write the ``__pycache__`` bytecode of :data:`PACKAGES`, as an install or a first import would."""
    for package in PACKAGES:
        assert compileall.compile_dir(ROOT / package, quiet=1), f"{package} does not byte-compile"


def child_cpu(command: list[str]) -> tuple[float, str]:
    """The user + system CPU seconds of ``command`` run to its end, and its stdout."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), done.stdout


def interleaved_rounds() -> dict[str, list[float]]:
    """Each command once per round, in turn, so that a change of load falls on all of them."""
    times: dict[str, list[float]] = {name: [] for name in COMMANDS}
    for _ in range(ROUNDS):
        for name, command in COMMANDS.items():
            times[name].append(child_cpu(command)[0])
    return times


def test_startup_cpu_against_plain_casadi_script(benchmark) -> None:
    compile_project()
    _, plain_out = child_cpu(COMMANDS["plain_casadi"])
    _, solve_out = child_cpu(COMMANDS["solve"])
    assert json.loads(solve_out)["objective"] == pytest.approx(float(plain_out), rel=1e-6)
    times = benchmark.pedantic(interleaved_rounds, rounds=1, iterations=1)
    median = {name: statistics.median(values) for name, values in times.items()}
    ratios = {f"{name}_over_plain": median[name] / median["plain_casadi"] for name in COMMANDS}
    benchmark.extra_info |= {f"{name}_cpu_s": value for name, value in median.items()} | ratios
    print()
    for name, value in median.items():
        print(f"{name:>12}: {value:.3f} s CPU, {ratios[f'{name}_over_plain']:.2f}x the plain script")
    assert ratios["solve_over_plain"] <= 2.0
    assert median["help"] < 0.5 and median["validate"] < 0.5
