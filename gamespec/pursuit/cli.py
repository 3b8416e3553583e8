"""``gamespec pursuit ...``: commands of the pursuit-evasion area (mounted in :mod:`gamespec.cli`)."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

pursuit_app = typer.Typer(no_args_is_help=True, help="Pursuit-evasion studies (thesis ch. 2–3).")


@pursuit_app.command()
def study(
    file: Annotated[Path, typer.Argument(help="Study file (study: pure_pursuit_suboptimal_vs_optimal).")],
    out: Annotated[Path, typer.Option(help="Folder for the per-point results (a rerun resumes).")],
    workers: Annotated[int, typer.Option(min=1, help="Local processes.")] = 1,
    json_: Annotated[bool, typer.Option("--json", help="Print the table as JSON on stdout.")] = False,
) -> None:
    """Table 2.1: suboptimal (eq. 2.27) against optimal evasion from two pure-pursuit pursuers."""
    from gamespec.pursuit.study import load_study, run

    table = run(load_study(file), out, workers=workers)
    if json_:
        sys.stdout.write(json.dumps(table, indent=2) + "\n")
        return
    view = Table(title=f"Table 2.1 — {file.name} (percentage variation of t_c)")
    columns = ["v", "points", "solved", "average_variation_percent", "maximum_variation_percent"]
    for col in columns:
        view.add_column(col.replace("_variation_percent", " [%]"), justify="right")
    for row in table:
        view.add_row(*(f"{row[c]:.4g}" if isinstance(row[c], float) else str(row[c]) for c in columns))
    Console().print(view)
    Console(stderr=True).print(f"wrote {out / 'table.json'} and {out / 'table_2_1.png'}")
