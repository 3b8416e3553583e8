"""Saved Results the figure tests plot, so that they draw without solving: one folder per shipped
problem file (the studies aside) under ``tests/data/results/<file stem>/``, written by
:meth:`gamespec.Result.save` from a solve with settings that keep it short (the figures show what
was solved, at any mesh).

Regenerate after a change to a shipped file, to a kind's schema or to what a kind saves, from the
repository root: ``python -m tests.plots.fixtures`` (every file), or
``python -m tests.plots.fixtures STEM ...`` (those files). A fixture whose provenance spec hash no
longer matches its file under the same settings is stale: :func:`saved` refuses it with that command.
"""

from __future__ import annotations

import functools
import shutil
import sys
import time
from pathlib import Path

import gamespec
from gamespec.errors import GamespecError
from gamespec.specs.hashing import spec_hash

ROOT = Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "problems"
FIXTURES = ROOT / "tests" / "data" / "results"

FAST_KINDS = {
    "pursuit_scenario": ["time_step=0.05"],
    "lq_stochastic_game": ["method.monte_carlo.samples=20"],
    "flow_field_game": ["method.monte_carlo.samples=500"],
}
DESENSITIZED = [
    "cdoc_lqr_a_uncertain",
    "cdoc_lqr_b_uncertain",
    "cdoc_lqr_marginal",
    "zermelo_final_state_desensitized",
    "zermelo_fixed_final_sensitivity",
    "zermelo_seywald",
    "zermelo_trajectory_desensitized",
]
FAST_FILES = {
    "car_vs_train": ["method.refine=null", "transforms.1.rcs.monte_carlo.samples=100"],
} | {stem: ["transforms.0.desensitize.monte_carlo.samples=20"] for stem in DESENSITIZED}
"""Settings that keep a fixture's solve short and its folder small (a Monte Carlo keeps up to 50
sample paths), by kind and by file stem."""

FILES = sorted(p for p in PROBLEMS.rglob("*.yaml") if "study" not in p.stem)
"""The shipped problem files with figures (a study's figures are its store's)."""


class StaleFixture(AssertionError):
    """A saved Result that is missing or was made from another version of its file or schema."""


def overrides(path: Path) -> list[str]:
    """The ``--set`` assignments a fixture of ``path`` is solved with."""
    return FAST_KINDS.get(gamespec.load(path).kind, []) + FAST_FILES.get(path.stem, [])


@functools.cache
def spec_of(path: Path):
    """The spec a fixture of ``path`` is solved from: the file under :func:`overrides` (read once
    per process; not to be changed)."""
    return gamespec.load(path, overrides(path))


def saved(path: Path) -> gamespec.Result:
    """The saved Result of ``path``; :class:`StaleFixture`, with the command that regenerates it,
    when it is missing, no longer reads as a Result (a kind's metrics schema changed), or its
    provenance spec hash is not the file's under :func:`overrides`."""
    folder = FIXTURES / path.stem
    regenerate = f"regenerate it: python -m tests.plots.fixtures {path.stem}"
    if not (folder / "result.json").is_file():
        raise StaleFixture(f"{folder.relative_to(ROOT)} is missing; {regenerate}")
    try:
        result = gamespec.Result.load(folder)
    except GamespecError as error:
        unreadable = f"{folder.relative_to(ROOT)} no longer reads as a Result ({error})"
        raise StaleFixture(f"{unreadable}; {regenerate}") from None
    expected = spec_hash(spec_of(path))
    if result.provenance.spec_hash != expected:
        raise StaleFixture(
            f"{folder.relative_to(ROOT)} was solved from another version of {path.relative_to(ROOT)} "
            f"or its schema (spec hash {result.provenance.spec_hash}, the file's now {expected}); "
            + regenerate
        )
    return result


def write(path: Path) -> gamespec.Result:
    """Solve ``path`` under :func:`overrides` and save the Result as its fixture (the provenance's
    source relative to the repository, so the folder does not name this checkout)."""
    result = gamespec.solve(spec_of(path))
    source = Path(result.provenance.source)
    if source.is_absolute() and source.is_relative_to(ROOT):
        provenance = result.provenance.model_copy(update={"source": str(source.relative_to(ROOT))})
        result = result.model_copy(update={"provenance": provenance})
    folder = FIXTURES / path.stem
    shutil.rmtree(folder, ignore_errors=True)
    result.save(folder)
    return result


def main(stems: list[str]) -> None:
    """Write the fixtures of the files named by ``stems`` (all of them when empty)."""
    known = {p.stem: p for p in FILES}
    unknown = sorted(set(stems) - set(known))
    if unknown:
        sys.exit(f"no shipped problem file named {', '.join(unknown)}")
    for stem in stems or list(known):
        start = time.process_time()
        result = write(known[stem])
        size = sum(f.stat().st_size for f in (FIXTURES / stem).iterdir())
        cpu = time.process_time() - start
        print(f"{stem}: {result.status.value}, {cpu:.1f} s CPU, {size / 1024:.0f} KiB", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
