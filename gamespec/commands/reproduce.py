"""``gamespec reproduce``: run the thesis experiments shipped in ``problems/`` and set each number
against the thesis (registered in the ``gamespec.commands`` entry-point group, mounted by
:mod:`gamespec.cli`).

The experiments are data (:mod:`gamespec.commands.reproduction`, ``reproduce.yaml``): a file, its
``--set`` overrides, the metric to read and what the thesis says. Each distinct solve runs once; its
Result is saved under ``OUT/<experiment>/`` and its figures are drawn from the saved Result; the table
is printed and written beside them as ``OUT/reproduce.md`` and ``OUT/reproduce.csv``.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

if TYPE_CHECKING:
    from gamespec.commands.reproduction import Experiment

WIDTH = 200
"""Characters per line of the table where stdout is not a terminal (a file, a pipe)."""

reproduce_app = typer.Typer(invoke_without_command=True, help="Reproduce the thesis experiments.")


def _progress(total: int) -> tuple[AbstractContextManager[object], Callable[[str], None]]:
    """A rich progress bar on stderr where stderr is a terminal, else one plain line per run."""
    if not sys.stderr.isatty():
        done = iter(range(1, total + 1))

        def line(text: str) -> None:
            print(f"[{next(done)}/{total}] {text}", file=sys.stderr, flush=True)

        return nullcontext(), line
    from rich.console import Console
    from rich.progress import Progress

    bar = Progress(console=Console(stderr=True), transient=True)
    task = bar.add_task("reproducing", total=total)

    def advance(text: str) -> None:
        bar.update(task, description=text, advance=1)

    return bar, advance


def _run(experiment: Experiment, problems: Path, folder: Path) -> tuple[dict | None, str]:
    """Solve one experiment's file, save the Result in ``folder`` and draw it from the saved copy:
    (the Result's JSON, its status unless ``optimal``), or (None, why there is no Result)."""
    from gamespec.errors import GamespecError
    from gamespec.loader import load
    from gamespec.plotting import plot_result
    from gamespec.result import Result, Status
    from gamespec.solving import solve

    try:
        spec = load(problems / experiment.file, experiment.set)
        result = solve(spec, experiment.backend)
    except GamespecError as err:
        return None, " ".join(str(err).split())
    result.save(folder)
    plot_result(Result.load(folder), folder)
    status = "" if result.status is Status.OPTIMAL else result.status.value
    return json.loads(result.to_json(arrays=False)), status


@reproduce_app.callback()
def reproduce(
    chapter: Annotated[
        list[int] | None,
        typer.Option("--chapter", metavar="N", help="Only this thesis chapter (repeatable)."),
    ] = None,
    out: Annotated[Path, typer.Option("--out", help="Folder for the Results, figures and table.")] = Path(
        "reproduction"
    ),
    problems: Annotated[Path, typer.Option(help="The shipped problems folder.")] = Path("problems"),
    manifest: Annotated[
        Path | None, typer.Option(help="A manifest of experiments (default: the shipped one).")
    ] = None,
) -> None:
    """Run the thesis experiments and print one table: thesis value, gamespec value, verdict, reason."""
    from rich.console import Console
    from rich.markup import escape
    from rich.table import Table

    from gamespec.commands.reproduction import (
        SHOWN,
        load_manifest,
        read_metric,
        table_rows,
        write_csv,
        write_markdown,
    )
    from gamespec.result import writable_folder

    experiments = [e for e in load_manifest(manifest).experiments if not chapter or e.chapter in chapter]
    writable_folder(out)
    runs: dict[tuple, Experiment] = {}
    for e in experiments:
        runs.setdefault(e.run_key, e)
    results: dict[tuple, tuple[dict | None, str]] = {}
    bar, advance = _progress(len(runs))
    with bar:
        for key, first in runs.items():
            advance(f"{first.file} {' '.join(first.set)}".strip())
            results[key] = _run(first, problems, out / first.name)
    values: dict[str, float | None] = {}
    statuses: dict[str, str] = {}
    for e in experiments:
        data, statuses[e.name] = results[e.run_key]
        values[e.name] = None if data is None else read_metric(data, e.metric)
    rows = table_rows(experiments, values, statuses)
    view = Table(title="gamespec reproduce: the thesis experiments")
    for column in SHOWN:
        view.add_column(column, overflow="fold")
    for row in rows:
        view.add_row(*(escape(row[c]) for c in SHOWN))
    Console(width=None if sys.stdout.isatty() else WIDTH).print(view)
    markdown, table = write_markdown(rows, out / "reproduce.md"), write_csv(rows, out / "reproduce.csv")
    print(f"wrote {markdown} and {table}", file=sys.stderr)
    failed = [e.name for e in experiments if values[e.name] is None]
    if failed:
        print(f"error: {len(failed)} experiments have no value: {', '.join(failed)}", file=sys.stderr)
        raise typer.Exit(1)
