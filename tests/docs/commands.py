"""The commands the documentation quotes, collected from where they are written, and what each claims.

Sources: the comments of every problem file (``problems/**/*.yaml``) and the fenced ``bash`` blocks of
``README.md`` and ``docs/**/*.md``. A *command line* is a line that starts with ``gamespec`` (after the
``#`` of a YAML comment), continued over lines that end in ``\\``; the line after it is its *claim*,
which starts with ``→`` (after ``#``, in a YAML comment and in a bash block alike). The syntax is
documented in ``docs/contributing.md``:

    gamespec solve problems/ocp/brachistochrone.yaml
    # → optimal, t_final = 1.80160 (± 1e-5)  [1.1 s CPU]

- the head: a status (``optimal``, ``feasible``, ... — the exit code follows from it: 0 for a status
  with a usable solution, else 1), or ``exit N`` for a command that prints no Result, or
  ``not run: REASON`` for a command that needs what a test cannot have (a Dask cluster);
- then ``name = value (± tol)`` pairs, ``name`` a field of ``gamespec solve --json`` (``objective``,
  ``t_final``) or a dotted path into it (``metrics.monte_carlo.collision_probability``,
  ``checks.max_defect``); ``(± 2 %)`` is relative; ``name = text`` compares text exactly;
- last, in brackets, the CPU time measured when the claim was written, and ``slow`` when that is
  at least :data:`SLOW_CPU_S` (the test then runs only with ``-m slow``).

Commands of a line joined by ``&&`` run in order (the gamespec ones; an install step is not run),
each must exit 0 unless it is the last one run, and the figures are read from the line's ``solve``.
A command that reads a folder an earlier command of the same page or file wrote (``--out DIR``, then
``gamespec plot DIR``) runs that command first. Every command runs in a fresh folder in which
``problems`` is the shipped one, so relative ``--out`` folders and study stores land there.

Run ``python -m tests.docs.commands [SUBSTRING ...]`` to measure the commands again (each in its own
process): it prints each one's exit codes, status, CPU time and the figures of its claim.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import re
import resource
import shlex
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
SLOW_CPU_S = 2.5
"""A command whose recorded CPU time reaches this many seconds is tagged ``slow``."""
DEFAULT_BUDGET_CPU_S = 38.0
"""The recorded CPU time of all commands of the default suite together stays under this (raised
from 35 s when the chapter-7 Q = 0 run, 0.9 s since its best responses skip unread checks, stopped
being slow; the whole default suite then took 2 min 41 s on two idle cores)."""
SUBCOMMANDS = (
    "solve",
    "validate",
    "show",
    "schema",
    "sweep",
    "results",
    "plot",
    "compare",
    "pursuit",
    "backends",
    "reproduce",
)
OK_STATUSES = ("optimal", "feasible", "simulated")
STATUSES = (
    *OK_STATUSES,
    "converged",
    "locally_infeasible",
    "infeasible",
    "unbounded",
    "iteration_limit",
    "time_limit",
    "not_converged",
    "cycling",
    "diverged",
    "numerical_error",
    "error",
)
ARROW = "→"
STRAY = re.compile(rf"(?<![`\w])gamespec (?:{'|'.join(SUBCOMMANDS)})\b")
FIGURE = re.compile(
    r"(?P<name>[A-Za-z_][\w.]*)\s*=\s*(?P<value>[^\s(,]+)"
    r"(?:\s*\(±\s*(?P<tol>[0-9.eE+-]+)\s*(?P<percent>%)?\))?"
)
TAGS = re.compile(r"\[(?:(?P<slow>slow),\s*)?(?P<cpu>[0-9.]+) s CPU\]\s*$")


class ClaimError(ValueError):
    """A claim that does not follow the syntax, named by its source and line."""


@dataclass(frozen=True)
class Figure:
    """``name = value (± tol)``: a number within ``tol`` (relative when ``relative``), or a text."""

    name: str
    value: float | str
    tolerance: float = 0.0
    relative: bool = False

    def holds(self, measured: object) -> bool:
        """Whether ``measured`` (read from the JSON Result) is what the figure says."""
        if isinstance(self.value, str):
            return str(measured) == self.value
        if isinstance(measured, bool) or not isinstance(measured, int | float) or math.isnan(measured):
            return False
        bound = self.tolerance * abs(self.value) if self.relative else self.tolerance
        return abs(measured - self.value) <= bound


@dataclass(frozen=True)
class Claim:
    """What a command line ends with: a status or exit code, figures, and its recorded CPU time."""

    status: str | None = None
    exit_code: int = 0
    figures: tuple[Figure, ...] = ()
    cpu_s: float | None = None
    slow: bool = False
    not_run: str | None = None


@dataclass
class Command:
    """One documented command line: where it is written, its ``gamespec`` parts and its claim."""

    source: str
    line: int
    text: str
    parts: list[list[str]]
    claim: Claim | None
    needs: list[Command] = field(default_factory=list)

    @property
    def id(self) -> str:
        return f"{self.source}:{self.line}"

    @property
    def outputs(self) -> set[str]:
        """The folders this line writes (``--out DIR``)."""
        return {argv[i + 1] for argv in self.parts for i, a in enumerate(argv[:-1]) if a == "--out"}


def parse_claim(text: str, where: str) -> Claim:
    """The claim written after ``→`` (without the arrow)."""
    text = text.strip()
    if text.startswith("not run:"):
        reason = text.removeprefix("not run:").strip()
        if not reason:
            raise ClaimError(f"{where}: 'not run:' needs a reason")
        return Claim(not_run=reason)
    cpu_s, slow = None, False
    tags = TAGS.search(text)
    if tags:
        cpu_s, slow = float(tags["cpu"]), bool(tags["slow"])
        text = text[: tags.start()].rstrip()
    head, _, rest = text.partition(",")
    head = head.strip()
    status, exit_code = None, 0
    if head.startswith("exit "):
        try:
            exit_code = int(head.removeprefix("exit "))
        except ValueError:
            raise ClaimError(f"{where}: 'exit' needs an integer, got {head!r}") from None
    elif head in STATUSES:
        status = head
        exit_code = 0 if head in OK_STATUSES else 1
    else:
        raise ClaimError(f"{where}: a claim starts with a status ({', '.join(STATUSES)}) or 'exit N'")
    figures = []
    rest = rest.strip()
    while rest:
        match = FIGURE.match(rest)
        if match is None:
            raise ClaimError(f"{where}: cannot read {rest!r} as 'name = value (± tol)'")
        figures.append(_figure(match, where))
        rest = rest[match.end() :].strip().removeprefix(",").strip()
    if figures and status is None:
        raise ClaimError(f"{where}: figures are read from a solve's Result: give its status")
    return Claim(status, exit_code, tuple(figures), cpu_s, slow)


def _figure(match: re.Match, where: str) -> Figure:
    try:
        value: float | str = float(match["value"])
    except ValueError:
        if match["tol"] is not None:
            raise ClaimError(f"{where}: a tolerance needs a number, got {match['value']!r}") from None
        return Figure(match["name"], match["value"])
    if match["tol"] is None:
        raise ClaimError(f"{where}: {match['name']} = {match['value']} needs a tolerance (± tol)")
    return Figure(
        match["name"], value, float(match["tol"]) / (100 if match["percent"] else 1), bool(match["percent"])
    )


def _split_chain(text: str, where: str) -> list[list[str]]:
    """The ``gamespec`` commands of a line (joined by ``&&``), each without the word ``gamespec``."""
    parts = []
    for piece in text.split("&&"):
        argv = shlex.split(piece, comments=True)
        if argv and argv[0] == "gamespec":
            parts.append(argv[1:])
    if not parts:
        raise ClaimError(f"{where}: no gamespec command in {text!r}")
    return parts


def _commands_in_lines(lines: list[tuple[int, str]], source: str, file_arg: str | None) -> list[Command]:
    """Command lines and their claims among ``lines`` (number, text without the comment marker)."""
    found: list[Command] = []
    i = 0
    while i < len(lines):
        number, text = lines[i]
        stripped = text.strip()
        if not any(piece.strip().startswith("gamespec ") for piece in stripped.split("&&")):
            if STRAY.search(stripped) and not stripped.startswith(ARROW):
                raise ClaimError(f"{source}:{number}: a command inside a sentence; put it on its own line")
            i += 1
            continue
        joined = stripped
        while joined.endswith("\\") and i + 1 < len(lines):
            i += 1
            joined = joined[:-1].rstrip() + " " + lines[i][1].strip()
        if file_arg is not None:
            joined = re.sub(r"\bFILE\b", file_arg, joined)
        where = f"{source}:{number}"
        claim = None
        if i + 1 < len(lines) and lines[i + 1][1].strip().startswith(ARROW):
            i += 1
            claim = parse_claim(lines[i][1].strip().removeprefix(ARROW), where)
        found.append(Command(source, number, joined, _split_chain(joined, where), claim))
        i += 1
    return found


def yaml_commands(path: Path) -> list[Command]:
    """The commands in the comments of a problem file (``FILE`` stands for the file itself)."""
    source = path.relative_to(ROOT).as_posix()
    lines = [
        (n, line.strip()[1:])
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if line.strip().startswith("#")
    ]
    return _commands_in_lines(lines, source, file_arg=source)


FENCE = re.compile(r"^(`{3,})(\w*)\s*$")
EXAMPLE_LANGUAGES = ("markdown", "text")
"""Blocks that show text as it is written (the syntax itself), whose commands are not run."""


def markdown_commands(path: Path) -> list[Command]:
    """The commands in the fenced ``bash`` blocks of a Markdown page (a claim line is a comment); a
    block inside a longer fence, or fenced as ``markdown`` or ``text``, is an example, not run."""
    source = path.relative_to(ROOT).as_posix()
    found: list[Command] = []
    block: list[tuple[int, str]] | None = None
    opening, language, start = "", "", 0
    for number, line in enumerate(path.read_text().splitlines(), 1):
        fence = FENCE.match(line.strip())
        if fence and block is None:
            block, opening, language, start = [], fence[1], fence[2], number
        elif fence and fence[1] == opening and not fence[2]:
            if language == "bash":
                text = [(n, t[1:] if t.strip().startswith(f"# {ARROW}") else t) for n, t in block]
                found += _commands_in_lines(text, source, file_arg=None)
            elif language not in EXAMPLE_LANGUAGES and any(
                t.strip().startswith("gamespec ") for _, t in block
            ):
                raise ClaimError(f"{source}:{start}: a block with gamespec commands is fenced as ```bash")
            block = None
        elif block is not None:
            block.append((number, line))
    return found


def _link_prerequisites(commands: list[Command]) -> None:
    """Each command needs the earlier commands of its page or file that write a folder it names."""
    for i, command in enumerate(commands):
        named = {a for argv in command.parts for a in argv}
        for earlier in commands[:i]:
            not_run = earlier.claim is not None and earlier.claim.not_run is not None
            if earlier.source == command.source and earlier.outputs & named and not not_run:
                command.needs.append(earlier)


def documented_commands() -> list[Command]:
    """Every command of the problem files, README.md and docs/, in file order."""
    commands: list[Command] = []
    for path in sorted((ROOT / "problems").rglob("*.yaml")):
        commands += yaml_commands(path)
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]:
        commands += markdown_commands(path)
    _link_prerequisites(commands)
    return commands


@dataclass
class Outcome:
    """What running a command line gave: each part's exit code, the solve's JSON Result, CPU time."""

    exit_codes: list[int]
    result: dict[str, Any] | None
    cpu_s: float
    stderr: str

    def value(self, name: str) -> object:
        """A field of the JSON Result, or a dotted path into it (list items by index)."""
        from gamespec.commands.reproduction import dotted

        return dotted(self.result, name)


def _cpu_s() -> float:
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


@contextlib.contextmanager
def workspace(folder: Path) -> Iterator[Path]:
    """``folder`` as the current directory, with ``problems`` linked to the shipped problem files."""
    link = folder / "problems"
    if not link.exists():
        link.symlink_to(ROOT / "problems", target_is_directory=True)
    previous = Path.cwd()
    os.chdir(folder)
    try:
        yield folder
    finally:
        os.chdir(previous)


def run_line(command: Command) -> Outcome:
    """Run a command line's ``gamespec`` parts in-process (:func:`gamespec.cli.run`, the code path of
    the console script) in the current directory; a ``solve`` gets ``--json`` so that its Result can be
    read (the summary table it would print instead is made from the same Result)."""
    from gamespec.cli import run

    codes: list[int] = []
    result = None
    errors = io.StringIO()
    start = _cpu_s()
    for argv in command.parts:
        is_solve = argv[0] == "solve"
        args = [*argv, "--json"] if is_solve and "--json" not in argv else argv
        out = io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(errors):
            code = run(args)
        codes.append(code)
        if is_solve and out.getvalue().strip():
            result = json.loads(out.getvalue())
        if code != 0:
            break
    return Outcome(codes, result, _cpu_s() - start, errors.getvalue())


def mismatches(command: Command, outcome: Outcome) -> list[str]:
    """How the outcome differs from the claim (empty when the claim holds)."""
    claim = command.claim
    assert claim is not None and claim.not_run is None
    problems = []
    codes = outcome.exit_codes
    if claim.exit_code == 0:
        held = codes == [0] * len(command.parts)
    else:
        held = all(c == 0 for c in codes[:-1]) and codes[-1] == claim.exit_code
    if not held:
        problems.append(f"exit codes {codes}, claimed {claim.exit_code} at the end")
    if claim.status is not None:
        measured = outcome.value("status")
        if measured != claim.status:
            problems.append(f"status {measured}, claimed {claim.status} ({outcome.value('message')})")
    for figure in claim.figures:
        measured = outcome.value(figure.name)
        if not figure.holds(measured):
            tol = f"{figure.tolerance:g}" + (" relative" if figure.relative else "")
            problems.append(f"{figure.name} = {measured}, claimed {figure.value} (± {tol})")
    return problems


def _warm_up() -> None:
    """Import the libraries that solves and plots import, so that a command's measured CPU time is
    its own, as in the test suite, where one process runs them all."""
    import importlib

    for name in ("casadi", "cvxpy", "matplotlib.pyplot", "pyomo.environ", "scipy.integrate", "sympy"):
        importlib.import_module(name)
    importlib.import_module("gamespec.solving")


def _measure_one(identifier: str) -> dict[str, Any]:
    """Run one command (and what it needs) in a fresh folder; the outcome as a JSON-ready dict."""
    import tempfile
    import warnings

    warnings.simplefilter("ignore")
    _warm_up()
    commands = {c.id: c for c in documented_commands()}
    command = commands[identifier]
    with tempfile.TemporaryDirectory() as tmp, workspace(Path(tmp)):
        for needed in command.needs:
            run_line(needed)
        outcome = run_line(command)
    figures = [f.name for f in command.claim.figures] if command.claim else []
    names = dict.fromkeys([*figures, "objective", "t_final"])
    return {
        "exit_codes": outcome.exit_codes,
        "status": outcome.value("status"),
        "message": outcome.value("message"),
        "cpu_s": round(outcome.cpu_s, 2),
        "values": {name: outcome.value(name) for name in names},
        "mismatches": mismatches(command, outcome) if command.claim and not command.claim.not_run else None,
        "stderr": outcome.stderr[-400:],
    }


def main(argv: list[str]) -> None:
    """Measure the documented commands whose ``source:line`` or text contains one of ``argv``."""
    import subprocess

    if argv[:1] == ["--one"]:
        sys.stdout.write(json.dumps(_measure_one(argv[1])) + "\n")
        return
    timeout = 900.0
    for command in documented_commands():
        if argv and not any(s in command.id or s in command.text for s in argv):
            continue
        if command.claim is not None and command.claim.not_run:
            print(f"{command.id}  {command.text}\n    not run: {command.claim.not_run}", flush=True)
            continue
        start = time.monotonic()
        try:
            run = subprocess.run(
                [sys.executable, "-m", "tests.docs.commands", "--one", command.id],
                cwd=ROOT,
                capture_output=True,
                text=True,
                timeout=timeout,
            )
            report = run.stdout.strip().splitlines()[-1] if run.stdout.strip() else run.stderr[-600:]
        except subprocess.TimeoutExpired:
            report = f"timed out after {timeout:.0f} s"
        wall = time.monotonic() - start
        print(f"{command.id}  {command.text}\n    ({wall:.0f} s wall) {report}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
