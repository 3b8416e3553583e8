"""The command line (DESIGN.md, "CLI"): validate, solve, compare, show, plot, schema, backends.

Area commands (``gamespec pursuit ...``) are Typer apps registered in the ``gamespec.commands``
entry-point group, mounted under their entry-point name; the core imports none of them by name.

Bad input is exit code 2 with one line on stderr; a solve that fails is exit code 1 with one line
saying why; tracebacks are for bugs only.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Annotated

import typer
import yaml
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from gamespec import registry
from gamespec.errors import GamespecError
from gamespec.loader import load
from gamespec.result import Result, writable_folder
from gamespec.studies.compare import (
    LEGEND,
    compare_backends,
    comparison_table,
    parse_backend_list,
    row_notes,
)

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="gamespec: declarative optimal control and differential games on interchangeable backends.",
)
console = Console()
err_console = Console(stderr=True)
for _area in registry.names("gamespec.commands"):
    app.add_typer(registry.load("gamespec.commands", _area), name=_area)

FileArg = Annotated[Path, typer.Argument(help="Problem file (.yaml, .toml or .json).")]
SetOpt = Annotated[
    list[str] | None,
    typer.Option("--set", help="Override a value: dotted.path=value (repeatable)."),
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print the result as JSON on stdout.")]
OutOpt = Annotated[Path | None, typer.Option("--out", help="Folder to save results into.")]


def _fmt(value: object) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return "—" if value is None else str(value)


@app.command()
def validate(file: FileArg, set_: SetOpt = None) -> None:
    """Check a problem file; exit 0 when valid, exit 2 with the reason otherwise."""
    spec = load(file, set_ or [])
    console.print(f"[green]valid[/green] {file} (kind {spec.kind}, name {spec.name})")


@app.command()
def solve(
    file: FileArg,
    backend: Annotated[str | None, typer.Option(help="Backend name (default: the file's).")] = None,
    set_: SetOpt = None,
    out: OutOpt = None,
    json_: JsonOpt = False,
    plot: Annotated[bool, typer.Option("--plot", help="Also write plots (into --out or .).")] = False,
) -> None:
    """Solve a problem file and print a summary (or the Result as JSON)."""
    from gamespec.solving import solve as run_solve

    spec = load(file, set_ or [])
    if out is not None:
        writable_folder(out)
    with err_console.status(f"solving {spec.name} ...", spinner="dots"):
        result = run_solve(spec, backend)
    if out is not None:
        result.save(out)
    if plot:
        from gamespec.plotting import plot_result

        for path in plot_result(result, out or Path(".")):
            err_console.print(f"wrote {path}")
    if json_:
        sys.stdout.write(result.to_json() + "\n")
    else:
        _print_summary(result)
        if out is not None:
            console.print(f"saved to {out}/")
    if not result.ok:
        print(
            f"error: {spec.name}: solve ended with status {result.status.value}: {result.message}",
            file=sys.stderr,
        )
        raise typer.Exit(1)


def _print_summary(result: Result) -> None:
    table = Table(title=f"{result.problem} on {result.backend}", show_header=False)
    for key, value in result.summary().items():
        if key in ("problem",) or value in (None, ""):
            continue
        table.add_row(key, _fmt(value))
    for key, value in result.metrics.items():
        if isinstance(value, int | float | str):
            table.add_row(key, _fmt(value))
    console.print(table)


@app.command()
def compare(
    file: FileArg,
    backends: Annotated[str, typer.Option(help="Comma-separated backends, each NAME or NAME:SOLVER.")],
    set_: SetOpt = None,
    out: OutOpt = None,
    json_: JsonOpt = False,
) -> None:
    """Solve one file on several backends with the same discretization; one table."""
    spec = load(file, set_ or [])
    entries = parse_backend_list(backends)
    if out is not None:
        writable_folder(out)
    rows = compare_backends(spec, entries, out=out, progress=err_console)
    if json_:
        sys.stdout.write(json.dumps(rows, indent=2) + "\n")
    else:
        console.print(comparison_table(rows, f"{spec.name}: backend comparison"))
        console.print(LEGEND, style="dim", highlight=False)
        for note in row_notes(rows):
            console.print(note, markup=False, highlight=False)
    if not any(row.get("status") in ("optimal", "feasible") for row in rows):
        print(f"error: {spec.name}: no backend solved the problem", file=sys.stderr)
        raise typer.Exit(1)


@app.command()
def sweep(
    file: FileArg,
    param: Annotated[list[str], typer.Option(help="name=a:b:n or name=v1,v2 (repeatable: a grid).")],
    out: Annotated[Path, typer.Option(help="Folder for the per-point results (a rerun resumes).")],
    backend: Annotated[str | None, typer.Option(help="Backend name (default: the file's).")] = None,
    workers: Annotated[int, typer.Option(min=1, help="Local processes.")] = 1,
    set_: SetOpt = None,
    json_: JsonOpt = False,
) -> None:
    """Solve a file over a grid of parameter values; one row per point, saved as it finishes."""
    from gamespec.studies.sweep import parse_range
    from gamespec.studies.sweep import sweep as run_sweep

    load(file, set_ or [])
    ranges = [parse_range(p) for p in param]
    rows = run_sweep(file, ranges, out=out, overrides=tuple(set_ or []), backend=backend, workers=workers)
    if json_:
        sys.stdout.write(json.dumps(rows, indent=2) + "\n")
        return
    names = [name for name, _ in ranges]
    table = Table(title=f"sweep of {file.name}")
    for col in [*names, "status", "objective", "t_final", "solve_time_s"]:
        table.add_column(col, justify="right")
    for row in rows:
        table.add_row(*(_fmt(row.get(c)) for c in [*names, "status", "objective", "t_final", "solve_time_s"]))
    console.print(table)
    failed = [r for r in rows if r["status"] not in ("optimal", "feasible")]
    if failed:
        print(f"error: {len(failed)} of {len(rows)} points did not solve", file=sys.stderr)
        raise typer.Exit(1)


@app.command()
def show(
    file: FileArg,
    transformed: Annotated[bool, typer.Option(help="Print the spec the backend actually solves.")] = False,
    backend: Annotated[str | None, typer.Option(help="Backend whose input to show.")] = None,
    set_: SetOpt = None,
) -> None:
    """Print the (validated, optionally transformed) problem as YAML."""
    spec = load(file, set_ or [])
    if transformed:
        from gamespec.solving import transformed as transformed_spec

        spec = transformed_spec(spec, backend)
    data = spec.model_dump(mode="json", exclude_defaults=False)
    sys.stdout.write(yaml.safe_dump(data, sort_keys=False, allow_unicode=True))


@app.command()
def plot(
    result: Annotated[Path, typer.Argument(help="A saved Result folder (or its result.json).")],
    out: OutOpt = None,
    animate: Annotated[bool, typer.Option(help="Also write an animation where the kind has one.")] = False,
) -> None:
    """Draw a saved Result (states, controls, paths; kind-specific figures), or a sweep folder's
    cost/sensitivity trade-off when its points are desensitized Results."""
    from gamespec.plotting import plot_result

    if (result / "points").is_dir():
        from gamespec.desensitize.plotting import plot_tradeoff

        for path in plot_tradeoff(result, writable_folder(out or result)):
            console.print(f"wrote {path}")
        return
    loaded = Result.load(result)
    folder = writable_folder(out or (result if result.is_dir() else result.parent))
    for path in plot_result(loaded, folder, animate=animate):
        console.print(f"wrote {path}")


@app.command()
def schema(
    kind: Annotated[str | None, typer.Argument(help="Problem kind (all kinds if omitted).")] = None,
) -> None:
    """Print the JSON Schema of problem files."""
    from gamespec.specs.schema import json_schema

    sys.stdout.write(json.dumps(json_schema(kind), indent=2) + "\n")


@app.command()
def backends() -> None:
    """List installed backends: whether each is available (and why not), its kinds and features."""
    from rich import box

    table = Table(title="gamespec backends", box=box.SIMPLE_HEAD, show_edge=False)
    table.add_column("backend", no_wrap=True)
    table.add_column("kinds")
    table.add_column("available, features, package")
    for name in registry.names("gamespec.backends"):
        try:
            cls = registry.backend_class(name)
        except (ImportError, GamespecError) as err:
            table.add_row(name, "", f"[red]no[/red]: cannot load ({escape(str(err))})")
            continue
        avail = cls.available()
        status = "[green]yes[/green]" if avail.ok else "[red]no[/red]"
        details = [f"{status}: {escape(avail.reason)}"]
        if cls.features:
            details.append(f"features: {', '.join(sorted(cls.features))}")
        details.append(f"from {registry.distribution('gamespec.backends', name)}")
        table.add_row(name, "\n".join(sorted(cls.kinds)), "\n".join(details), end_section=True)
    console.print(table)


def run(argv: list[str] | None = None) -> int:
    """Run the CLI on ``argv`` and return the exit code (user errors → 2, one line on stderr)."""
    try:
        app(args=argv, prog_name="gamespec")
    except SystemExit as exit_:
        return exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None else 1)
    except GamespecError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    return 0


def main() -> None:
    """Console-script entry point."""
    sys.exit(run())
