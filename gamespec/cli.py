"""The command line (DESIGN.md, "CLI"): validate, solve, compare, sweep, results, show, plot, schema,
backends.

Area commands (``gamespec pursuit ...``) are Typer apps registered in the ``gamespec.commands``
entry-point group, mounted under their entry-point name; the core imports none of them by name.

Bad input is exit code 2 with one line on stderr; a solve that fails is exit code 1 with one line
saying why; tracebacks are for bugs only.
"""

from __future__ import annotations

import json
import logging
import sys
import warnings
from collections.abc import Iterator
from contextlib import AbstractContextManager, contextmanager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer

from gamespec import registry
from gamespec.commands.options import AnalysesOpt, with_analyses
from gamespec.errors import GamespecError, SpecError

if TYPE_CHECKING:
    from rich.console import Console
    from rich.table import Table

    from gamespec.result import Result

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    rich_markup_mode=None,
    help="gamespec: declarative optimal control and differential games on interchangeable backends.",
)
_MOUNTED: set[str] = set()


def _console(stderr: bool = False) -> Console:
    """rich's console on stdout (or stderr), made on first use (:func:`gamespec.terminal.console`:
    unwrapped off a terminal); rich is imported only to print."""
    from gamespec.terminal import console

    return console(stderr)


def _spinner(text: str) -> AbstractContextManager[object]:
    """rich's spinner on stderr while ``text``'s work runs, where stderr is a terminal; elsewhere
    (a pipe, a file, ``--json`` in a script) it has no one to show to, and neither rich nor its
    refresh thread is started."""
    if not sys.stderr.isatty():
        return nullcontext()
    return _console(stderr=True).status(text, spinner="dots")


def _escape(text: str) -> str:
    from rich.markup import escape

    return escape(text)


def mount_commands() -> None:
    """Mount every Typer app of the ``gamespec.commands`` group (entry points, or
    :func:`gamespec.registry.register`) as ``gamespec NAME``, once each."""
    for name in registry.names("gamespec.commands"):
        if name not in _MOUNTED:
            app.add_typer(registry.load("gamespec.commands", name), name=name)
            _MOUNTED.add(name)


mount_commands()

FileArg = Annotated[Path, typer.Argument(help="Problem file (.yaml, .toml or .json).")]
SetOpt = Annotated[
    list[str] | None,
    typer.Option("--set", help="Override a value: dotted.path=value (repeatable)."),
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print the result as JSON on stdout.")]
OutOpt = Annotated[Path | None, typer.Option("--out", help="Folder to save results into.")]


SchedulerOpt = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        envvar="GAMESPEC_SCHEDULER",
        help="Address of a running Dask scheduler, e.g. tcp://host:8786 (env GAMESPEC_SCHEDULER).",
    ),
]
StudySchedulerOpt = Annotated[
    str | None,
    typer.Option(
        "--scheduler",
        help="Run a study kind on this Dask scheduler, e.g. tcp://host:8786 (else GAMESPEC_SCHEDULER, "
        "else the file's executor).",
    ),
]
InsecureOpt = Annotated[
    bool,
    typer.Option(
        "--insecure-scheduler",
        help="Reach a --scheduler on another machine without verified TLS: a scheduler can run code "
        "in this process (README, Security).",
    ),
]


def _version(value: bool) -> None:
    if value:
        from importlib.metadata import version

        _console().print(f"gamespec {version('gamespec')}", highlight=False)
        raise typer.Exit()


@app.callback()
def _main(
    version: Annotated[
        bool, typer.Option("--version", callback=_version, is_eager=True, help="Print the version and exit.")
    ] = False,
    quiet: Annotated[
        bool, typer.Option("--quiet", "-q", help="No progress on stderr (results and errors still print).")
    ] = False,
) -> None:
    """gamespec: declarative optimal control and differential games on interchangeable backends."""
    from gamespec.terminal import set_quiet

    set_quiet(quiet)


def _fmt(value: object) -> str:
    if isinstance(value, float):
        return f"{value:.6g}"
    return "—" if value is None else str(value)


@app.command()
def validate(file: FileArg, set_: SetOpt = None) -> None:
    """Check a problem file; exit 0 when valid, exit 2 with the reason otherwise."""
    from gamespec.loader import load

    spec = load(file, set_ or [])
    if spec.transforms:
        from gamespec.solving import check_requested

        check_requested(spec)
    for view, player, problem in _players(spec, with_transforms=True):
        from gamespec.solving import check_requested

        try:
            check_requested(problem)
        except SpecError as err:
            field = f"problem.players.{player}.{err.field}" if err.field else f"problem.players.{player}"
            raise SpecError(f"in {view}'s game: {err.reason}", field=field, source=str(file)) from None
    _console().print(f"[green]valid[/green] {file} (kind {spec.kind}, name {spec.name})")


def _players(spec: Any, with_transforms: bool = False) -> list[tuple[str, str, Any]]:
    """(game, player, best-response problem) of each player of a ``differential_game`` (none for
    any other kind, or, ``with_transforms``, when no player requests a transform):
    :func:`gamespec.games.problems.player_problems`. Nothing is imported for another kind (what
    ``validate`` imports: ``tests/core/test_startup_imports.py``)."""
    if spec.kind != "differential_game":
        return []
    if with_transforms and not any(p.transforms for p in spec.problem.players.values()):
        return []
    from gamespec.games.problems import player_problems

    return [(v, p, problem) for v, players in player_problems(spec).items() for p, problem in players.items()]


def _store_under(spec: Any, out: Path) -> Any:
    """A study kind's spec with a relative point store (the shipped files' ``runs/.../points``)
    moved under ``out``, keeping its last part (``OUT/points``, where ``gamespec results OUT`` and
    ``gamespec plot OUT`` find it): ``--out`` decides where a run's output lands. An absolute store
    is a place the user chose and is kept; any other spec is as it is."""
    store = getattr(spec, "store", None)
    if not isinstance(store, Path) or store.is_absolute():
        return spec
    return spec.model_copy(update={"store": out / store.name})


@app.command()
def solve(
    file: FileArg,
    backend: Annotated[str | None, typer.Option(help="Backend name (default: the file's).")] = None,
    set_: SetOpt = None,
    out: OutOpt = None,
    json_: JsonOpt = False,
    plot: Annotated[bool, typer.Option("--plot", help="Also write plots (into --out or .).")] = False,
    scheduler: StudySchedulerOpt = None,
    insecure_scheduler: InsecureOpt = False,
    analyses: AnalysesOpt = None,
) -> None:
    """Solve a problem file and print a summary (or the Result as JSON); a study kind runs on the
    Dask ``--scheduler`` when one is given."""
    from gamespec.loader import load
    from gamespec.result import writable_folder
    from gamespec.solving import solve as run_solve

    spec = load(file, with_analyses(set_, analyses))
    if out is not None:
        writable_folder(out)
        spec = _store_under(spec, out)
    options = _where_it_runs(spec, backend, scheduler, insecure_scheduler)
    with _spinner(f"solving {spec.name} ..."):
        result = run_solve(spec, backend, options=options)
    if out is not None:
        _remove_previous_figures(out)
        result.save(out)
    if plot:
        from gamespec.plotting import plot_result

        for path in plot_result(result, out or Path(".")):
            if not json_:
                _console().print(f"wrote {path}", markup=False, highlight=False)
    if json_:
        sys.stdout.write(result.to_json() + "\n")
    else:
        _print_summary(result)
        if out is not None:
            _console().print(f"saved to {out}/")
    if not result.ok:
        print(
            f"error: {spec.name}: solve ended with status {result.status.value}: {result.message}",
            file=sys.stderr,
        )
        raise typer.Exit(1)


def _where_it_runs(spec, backend: str | None, scheduler: str | None, insecure: bool) -> dict | None:
    """The study options ``--scheduler`` and ``--insecure-scheduler`` give, for a study kind (None
    when neither is given); a GamespecError for a kind a backend solves."""
    if not scheduler and not insecure:
        return None
    if registry.kind(spec.kind).study is None:
        from gamespec.solving import backend_name

        name = backend_name(spec, backend)
        raise GamespecError(
            f"--scheduler: backend {name!r} runs no study (a sweep takes --scheduler: gamespec sweep)"
        )
    return {"scheduler": scheduler, "insecure_scheduler": insecure}


FIGURE_SUFFIXES = (".png", ".gif", ".mp4")


def _remove_previous_figures(folder: Path) -> None:
    """Before a new Result is saved over an old one, delete the old one's figures so that no figure
    of another solve is left beside it (only in a folder that holds a saved Result)."""
    if not (folder / "result.json").exists():
        return
    for path in folder.iterdir():
        if path.is_file() and path.suffix in FIGURE_SUFFIXES:
            path.unlink()


def _print_summary(result: Result) -> None:
    """The kind's outcome first (:mod:`gamespec.summaries`), then status, timings and checks, then
    the other scalar metrics; each key once."""
    from rich.table import Table

    from gamespec.summaries import headline, outcome

    table = Table(title=headline(result), show_header=False)
    lead = outcome(result)
    for key, value in lead:
        table.add_row(_escape(key), _escape(_fmt(value)), style="bold")
    if lead:
        table.add_section()
    general = {k: v for k, v in result.summary().items() if k != "problem" and v not in (None, "")}
    for key, value in general.items():
        table.add_row(key, _escape(_fmt(value)))
    for key, value in result.metrics.items():
        if isinstance(value, int | float | str) and key not in general:
            table.add_row(key, _escape(_fmt(value)))
    _console().print(table)


@app.command()
def compare(
    file: FileArg,
    backends: Annotated[str, typer.Option(help="Comma-separated backends, each NAME or NAME:SOLVER.")],
    set_: SetOpt = None,
    out: OutOpt = None,
    json_: JsonOpt = False,
) -> None:
    """Solve one file on several backends with the same discretization; one table."""
    from gamespec.loader import load
    from gamespec.result import status_ok, writable_folder
    from gamespec.studies.compare import (
        LEGEND,
        compare_backends,
        comparison_table,
        parse_backend_list,
        row_notes,
    )

    spec = load(file, set_ or [])
    entries = parse_backend_list(backends)
    if out is not None:
        writable_folder(out)
    rows = compare_backends(spec, entries, out=out, progress=_console(stderr=True))
    if json_:
        sys.stdout.write(json.dumps(rows, indent=2) + "\n")
    else:
        _console().print(comparison_table(rows, f"{spec.name}: backend comparison"))
        _console().print(LEGEND, style="dim", highlight=False)
        for note in row_notes(rows):
            _console().print(note, markup=False, highlight=False)
    if not any(status_ok(row.get("status", "")) for row in rows):
        print(f"error: {spec.name}: no backend solved the problem", file=sys.stderr)
        raise typer.Exit(1)


ExecutorOpt = Annotated[
    str | None,
    typer.Option(
        "--executor",
        help="serial, process or dask (default: serial for one worker, process for more, dask with "
        "a scheduler).",
    ),
]
WorkersOpt = Annotated[int, typer.Option(min=1, help="Worker processes (a LocalCluster's size for dask).")]

SWEEP_COLUMNS = ("status", "objective", "t_final", "solve_time_s")


@app.command()
def sweep(
    file: FileArg,
    param: Annotated[list[str], typer.Option(help="name=a:b:n or name=v1,v2 (repeatable: a grid).")],
    out: Annotated[Path, typer.Option(help="Folder of the study store (a rerun resumes).")],
    backend: Annotated[str | None, typer.Option(help="Backend name (default: the file's).")] = None,
    executor: ExecutorOpt = None,
    workers: WorkersOpt = 1,
    scheduler: SchedulerOpt = None,
    insecure_scheduler: InsecureOpt = False,
    set_: SetOpt = None,
    json_: JsonOpt = False,
    analyses: AnalysesOpt = None,
) -> None:
    """Solve a file over a grid of parameter values; one row per point, saved as it finishes."""
    from gamespec.loader import load
    from gamespec.result import status_ok, writable_folder
    from gamespec.studies.executors import executor as make_executor
    from gamespec.studies.sweep import parse_range
    from gamespec.studies.sweep import sweep as run_sweep

    overrides = with_analyses(set_, analyses)
    load(file, overrides)
    ranges = [parse_range(p) for p in param]
    writable_folder(out)
    runner = make_executor(executor, workers, scheduler, insecure=insecure_scheduler)
    run = run_sweep(file, ranges, out=out, overrides=tuple(overrides), backend=backend, executor=runner)
    rows = list(run.values.values())
    if json_:
        sys.stdout.write(json.dumps(rows, indent=2) + "\n")
    else:
        names = [name for name, _ in ranges]
        _console().print(_rows_table(rows, [*names, *SWEEP_COLUMNS], f"sweep of {file.name}"))
        tally = f"{run.computed} computed now, {run.reused} reused"
        print(f"{len(rows)} points in {out} ({tally})", file=sys.stderr)
    failed = [r for r in rows if not status_ok(r["status"])]
    if failed:
        print(f"error: {len(failed)} of {len(rows)} points did not solve", file=sys.stderr)
        raise typer.Exit(1)


def _rows_table(rows: list[dict], columns: list[str], title: str) -> Table:
    from rich.table import Table

    table = Table(title=title)
    for col in columns:
        table.add_column(col, justify="right")
    for row in rows:
        table.add_row(*(_fmt(row.get(c)) for c in columns))
    return table


RESULT_COLUMNS = (
    "backend",
    "status",
    "objective",
    "t_final",
    "t_suboptimal",
    "t_optimal",
    "variation_percent",
    "solve_time_s",
)
"""Columns ``gamespec results`` shows after the swept parameters, where the rows have them; then
the headline numbers of the points' kinds (:func:`~gamespec.studies.export.headline_columns`)."""


def _result_trajectories(folder: Path, csv: Path | None, parquet: Path | None, json_: bool) -> None:
    """``gamespec results`` on one Result's folder: its summary (or JSON), its trajectories exported."""
    from gamespec.result import Result
    from gamespec.studies.export import write_csv, write_parquet
    from gamespec.studies.trajectories import trajectory_rows

    result = Result.load(folder)
    rows = trajectory_rows(result)
    if (csv or parquet) and not rows:
        raise GamespecError(f"{folder}: the Result has no trajectories to export")
    if json_:
        sys.stdout.write(result.to_json() + "\n")
    else:
        _print_summary(result)
    for path in (write_csv(rows, csv) if csv else None, write_parquet(rows, parquet) if parquet else None):
        if path is not None:
            print(f"wrote {path} ({len(rows)} rows)", file=sys.stderr)


@app.command()
def results(
    folder: Annotated[
        Path, typer.Argument(help="A study folder (a sweep's or compare's --out), or one Result's folder.")
    ],
    csv: Annotated[Path | None, typer.Option("--csv", help="Write every column as CSV here.")] = None,
    parquet: Annotated[Path | None, typer.Option("--parquet", help="Write a typed Parquet file.")] = None,
    json_: JsonOpt = False,
) -> None:
    """Print a study's table (sweep, compare, Table 2.1) and export it as CSV or Parquet; for one
    Result's folder, its summary, and its trajectories as the exported table."""
    from gamespec.studies.export import find_store, headline_columns, study_rows, write_csv, write_parquet
    from gamespec.studies.rows import study_meta

    if (folder / "result.json").is_file():
        _result_trajectories(folder, csv, parquet, json_)
        return
    store = find_store(folder)
    rows = study_rows(store)
    study = study_meta(store)
    for line in store.damaged:
        print(line, file=sys.stderr)
    if json_:
        sys.stdout.write(json.dumps(rows, indent=2) + "\n")
    else:
        present = {name for row in rows for name in row}
        wanted = dict.fromkeys([*study.parameters, *study.headline, *headline_columns(rows), *RESULT_COLUMNS])
        shown = [c for c in wanted if c in present]
        title = f"{study.type or 'study'} {study.problem}: {len(rows)} points".strip()
        _console().print(_rows_table(rows, shown or ["key"], title))
    for path in (write_csv(rows, csv) if csv else None, write_parquet(rows, parquet) if parquet else None):
        if path is not None:
            print(f"wrote {path}", file=sys.stderr)


@app.command()
def show(
    file: FileArg,
    transformed: Annotated[
        bool,
        typer.Option(
            help="Print the spec the backend actually solves (a differential game: each player's "
            "best-response problem in each player's game, transformed)."
        ),
    ] = False,
    backend: Annotated[str | None, typer.Option(help="Backend whose input to show.")] = None,
    set_: SetOpt = None,
) -> None:
    """Print the (validated, optionally transformed) problem as YAML."""
    import yaml

    from gamespec.loader import load

    spec = load(file, set_ or [])
    players = _players(spec) if transformed else []
    if players:
        from gamespec.solving import transformed as transformed_spec

        data: dict[str, Any] = {}
        for view, player, problem in players:
            solved = transformed_spec(problem).as_solved()
            data.setdefault(f"game of {view}", {})[player] = solved.model_dump(mode="json")
    else:
        if transformed:
            from gamespec.solving import transformed as transformed_spec

            spec = transformed_spec(spec, backend).as_solved()
        data = spec.model_dump(mode="json", exclude_defaults=False)
    sys.stdout.write(yaml.safe_dump(data, sort_keys=False, allow_unicode=True))


@app.command()
def plot(
    result: Annotated[Path, typer.Argument(help="A saved Result folder (or its result.json).")],
    out: OutOpt = None,
    animate: Annotated[bool, typer.Option(help="Also write an animation where the kind has one.")] = False,
) -> None:
    """Draw a saved Result (states, controls, paths; kind-specific figures), or a study folder
    (a sweep: outputs against each parameter, and the cost/sensitivity trade-off when its points are
    desensitized Results; a compare: bars per backend)."""
    from gamespec.plotting import plot_result
    from gamespec.result import Result, writable_folder
    from gamespec.studies.store import ResultStore, is_store

    folder = writable_folder(out or (result if result.is_dir() else result.parent))
    if is_store(result):
        from gamespec.studies.plots import plot_study

        store = ResultStore(result)
        paths = plot_study(store, folder)
        for line in store.damaged:
            print(line, file=sys.stderr)
    else:
        loaded = Result.load(result)
        paths = plot_result(loaded, folder, animate=animate)
        if animate and not any(p.suffix == ".gif" for p in paths):
            _console().print(f"no animation: a {loaded.kind} Result of this sort has none")
    for path in paths:
        _console().print(f"wrote {path}")


@app.command()
def schema(
    kind: Annotated[str | None, typer.Argument(help="Problem kind (all kinds if omitted).")] = None,
) -> None:
    """Print the JSON Schema of problem files."""
    from gamespec.specs.schema import json_schema

    sys.stdout.write(json.dumps(json_schema(kind), indent=2) + "\n")


@app.command()
def backends() -> None:
    """List installed backends, then the studies that run the study kinds: whether each is
    available (and why not), its kinds and features."""
    from rich import box
    from rich.table import Table

    table = Table(title="gamespec backends", box=box.SIMPLE_HEAD, show_edge=False)
    table.add_column("backend", no_wrap=True)
    table.add_column("kinds")
    table.add_column("available, features, package")
    studies = registry.names("gamespec.studies")
    for name in [*registry.names("gamespec.backends"), *studies]:
        group = "gamespec.studies" if name in studies else "gamespec.backends"
        try:
            cls = registry.load(group, name)
        except (ImportError, GamespecError) as err:
            table.add_row(name, "", f"[red]no[/red]: cannot load ({_escape(str(err))})")
            continue
        avail = cls.available()
        status = "[green]yes[/green]" if avail.ok else "[red]no[/red]"
        details = [f"{status}: {_escape(avail.reason)}"]
        if cls.features:
            details.append(f"features: {', '.join(sorted(cls.features))}")
        if group == "gamespec.studies":
            details.append("a study: runs many solves, each on the file's ocp_backend")
        details.append(f"from {registry.distribution(group, name)}")
        table.add_row(
            name, "\n".join(_kinds_through_transforms(cls.kinds)), "\n".join(details), end_section=True
        )
    _console().print(table)


def _kinds_through_transforms(kinds: frozenset[str]) -> list[str]:
    """A backend's own kinds, then each kind that lowering transforms turn into one of them, with the
    chain (``engagement (via engagement_to_ocp)``)."""
    steps = {n: registry.load("gamespec.transforms", n) for n in registry.names("gamespec.transforms")}
    via: dict[str, list[str]] = {k: [] for k in kinds}
    frontier = list(kinds)
    while frontier:
        target = frontier.pop()
        for name, step in steps.items():
            if step.target_kind == target and step.source_kind not in via:
                via[step.source_kind] = [name, *via[target]]
                frontier.append(step.source_kind)
    own = sorted(kinds)
    lowered = sorted(k for k in via if k not in kinds)
    return own + [f"{k} (via {' → '.join(via[k])})" for k in lowered]


_ClickException = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException")
"""Click's root exception (vendored by recent typer, a separate package before): usage errors."""


@contextmanager
def _quiet() -> Iterator[None]:
    """No warning is shown, and NumPy's floating-point errors are ignored where NumPy is imported
    already; where a command imports it later, they reach the same filter as warnings. NumPy is
    not imported for it: ``--help`` and ``validate`` of most files never need it."""
    numpy = sys.modules.get("numpy")
    matplotlib_log = logging.getLogger("matplotlib")
    level = matplotlib_log.level
    matplotlib_log.setLevel(logging.ERROR)  # its notes on axis limits are warnings too
    try:
        with warnings.catch_warnings(), numpy.errstate(all="ignore") if numpy else nullcontext():
            warnings.simplefilter("ignore")
            yield
    finally:
        matplotlib_log.setLevel(level)


def run(argv: list[str] | None = None) -> int:
    """Run the CLI on ``argv`` and return the exit code: user errors and usage errors → 2 with one
    line on stderr. Warnings (numpy's, a solver's) are not printed: what a solve found is in its
    Result's status, message and checks."""
    mount_commands()
    command = typer.main.get_command(app)
    try:
        with _quiet():
            code = command.main(args=argv, prog_name="gamespec", standalone_mode=False)
    except SystemExit as exit_:
        return exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None else 1)
    except GamespecError as err:
        print(f"error: {_one_line(str(err))}", file=sys.stderr)
        return 2
    except _ClickException as err:
        message = _one_line(err.format_message())
        if message:
            print(f"error: {message} (see 'gamespec --help')", file=sys.stderr)
        return err.exit_code
    except typer.Abort:
        print("error: aborted", file=sys.stderr)
        return 1
    return code if isinstance(code, int) else 0


def _one_line(text: str) -> str:
    return " ".join(text.split())


def main() -> None:
    """Console-script entry point."""
    sys.exit(run())
