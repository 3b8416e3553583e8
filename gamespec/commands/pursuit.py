"""``gamespec pursuit ...``: commands of the pursuit-evasion area (registered in the
``gamespec.commands`` entry-point group, mounted by :mod:`gamespec.cli`)."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer

from gamespec.commands.options import AnalysesOpt, with_analyses

pursuit_app = typer.Typer(no_args_is_help=True, help="Pursuit-evasion studies (thesis ch. 2–3).")

TABLE_COLUMNS = ("v", "points", "solved", "average_variation_percent", "maximum_variation_percent")


def _cell(value: object) -> str:
    if value is None:
        return "—"
    return f"{value:.4g}" if isinstance(value, float) else str(value)


@pursuit_app.command()
def study(
    file: Annotated[Path, typer.Argument(help="Problem file of kind pursuit_suboptimal_study.")],
    out: Annotated[
        Path | None,
        typer.Option(help="Save the Result and variation.png here, and the points in OUT/points."),
    ] = None,
    workers: Annotated[int | None, typer.Option(min=1, help="Processes (default: the file's).")] = None,
    executor: Annotated[
        str | None, typer.Option(help="serial, process or dask (default: the file's, else by --workers).")
    ] = None,
    scheduler: Annotated[
        str | None,
        typer.Option(envvar="GAMESPEC_SCHEDULER", help="Address of a running Dask scheduler."),
    ] = None,
    insecure_scheduler: Annotated[
        bool,
        typer.Option(
            "--insecure-scheduler",
            help="Reach a --scheduler on another machine without verified TLS (README, Security).",
        ),
    ] = False,
    set_: Annotated[
        list[str] | None, typer.Option("--set", help="Override a value: dotted.path=value (repeatable).")
    ] = None,
    json_: Annotated[bool, typer.Option("--json", help="Print the table as JSON on stdout.")] = False,
    analyses: AnalysesOpt = None,
) -> None:
    """Table 2.1: `gamespec solve` on a pursuit_suboptimal_study file, printed as the table.

    Resumes from the file's ``store`` (or OUT/points); the Result is the one `gamespec solve` gives.
    """
    from rich.table import Table

    from gamespec.errors import SpecError
    from gamespec.loader import load
    from gamespec.plotting import plot_result
    from gamespec.solving import solve
    from gamespec.terminal import console

    overrides = [*with_analyses(set_, analyses), *([f"store={out / 'points'}"] if out is not None else [])]
    spec = load(file, overrides)
    if spec.kind != "pursuit_suboptimal_study":
        reason = f"expected kind 'pursuit_suboptimal_study', got {spec.kind!r}"
        raise SpecError(reason, field="kind", source=str(file))
    chosen = {"workers": workers, "executor": executor, "scheduler": scheduler}
    chosen["insecure_scheduler"] = insecure_scheduler or None
    options = {"progress": True} | {name: value for name, value in chosen.items() if value is not None}
    result = solve(spec, options=options)
    if out is not None:
        result.save(out)
        for path in plot_result(result, out):
            if not json_:
                console().print(f"wrote {out / 'result.json'} and {path}", highlight=False)
    table = result.metrics.get("table", [])
    if json_:
        sys.stdout.write(json.dumps(table, indent=2) + "\n")
    else:
        view = Table(title=f"{result.problem} — {file.name} (percentage variation of t_c)")
        for col in TABLE_COLUMNS:
            view.add_column(col.replace("_variation_percent", " [%]"), justify="right")
        for row in table:
            view.add_row(*(_cell(row[c]) for c in TABLE_COLUMNS))
        console().print(view)
    if not result.ok:
        print(
            f"error: {spec.name}: study ended with status {result.status.value}: {result.message}",
            file=sys.stderr,
        )
        raise typer.Exit(1)
    if not json_:
        console().print(f"{result.status.value}: {result.message}", highlight=False)
