"""The reproduction report's data: the manifest of thesis experiments (``reproduce.yaml`` beside this
module), the verdict of each against the thesis, and the table as Markdown and CSV.

A row *holds* when every comparison the manifest gives holds: the gamespec value within ``tolerance``
of a thesis number, above (or below) another row's value where the thesis states an ordering (closed
loop above open loop, Fig. 5.2), or above (below) a number (a target out of reach). A row with
nothing to compare is ``withheld`` (the thesis withholds its number) or ``no thesis value``; a row
whose Result has no number at its metric is ``failed``. A value is read whatever the status (an
``infeasible`` covariance game still reports how far its target is out of reach); the status is
shown beside a value that is not ``optimal``. The ``reason`` of a row (a thesis inconsistency, a
reading chosen, a solution concept) is printed next to its verdict. Nothing here solves.
"""

from __future__ import annotations

import csv
import math
from importlib.resources import files
from pathlib import Path
from typing import Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, model_validator

from gamespec.errors import SpecError

MANIFEST = files("gamespec.commands") / "reproduce.yaml"
COLUMNS = ("experiment", "file", "reference", "thesis", "gamespec", "verdict", "reason")
SHOWN = ("experiment", "reference", "thesis", "gamespec", "verdict", "reason")
"""The columns printed on the terminal (the file is in the Markdown and CSV tables)."""


class Experiment(BaseModel):
    """One thesis experiment: which file to solve, which number to read, what the thesis says."""

    model_config = ConfigDict(extra="forbid")

    name: str = Field(description="Short unique name; other rows refer to it in above/below.")
    chapter: int = Field(ge=1, description="Thesis chapter (--chapter selects on it).")
    title: str = Field(description="What is measured, as the table shows it.")
    file: str = Field(description="Problem file, relative to the problems folder (--problems).")
    set: list[str] = Field(default_factory=list, description="--set overrides: dotted.path=value.")
    backend: str | None = Field(default=None, description="Backend (default: the file's).")
    metric: str = Field(description="Field of the JSON Result, or a dotted path into it (metrics.x.y).")
    reference: str = Field(description="Where the thesis reports it: equation, figure or table.")
    thesis: float | Literal["withheld"] | None = Field(
        default=None, description="The thesis' number, 'withheld' where it is not given, or none."
    )
    statement: str | None = Field(default=None, description="The thesis' claim where it is an ordering.")
    tolerance: float = Field(default=0.0, ge=0, description="|gamespec - thesis| for 'holds'.")
    above: str | float | None = Field(
        default=None, description="A row (by name) or a number that this value exceeds, as the thesis says."
    )
    below: str | float | None = Field(default=None, description="A row or a number this value stays under.")
    reason: str | None = Field(default=None, description="Why it differs, or the reading it holds under.")

    @property
    def run_key(self) -> tuple[str, tuple[str, ...], str | None]:
        """Rows with the same key read one solve."""
        return (self.file, tuple(self.set), self.backend)


class Manifest(BaseModel):
    """The experiments, in table order."""

    model_config = ConfigDict(extra="forbid")

    experiments: list[Experiment]

    @model_validator(mode="after")
    def _names(self) -> Manifest:
        names = [e.name for e in self.experiments]
        if len(set(names)) != len(names):
            raise ValueError("experiment names must be unique")
        for e in self.experiments:
            for other in (e.above, e.below):
                if isinstance(other, str) and other not in names:
                    raise ValueError(f"{e.name}: no experiment named {other!r}")
        return self


def load_manifest(path: Path | None = None) -> Manifest:
    """The shipped manifest, or the one at ``path`` (YAML, read with ``safe_load``)."""
    text = MANIFEST.read_text() if path is None else Path(path).read_text()
    try:
        return Manifest.model_validate(yaml.safe_load(text))
    except (ValueError, yaml.YAMLError) as err:
        raise SpecError(" ".join(str(err).split()), source=str(path or MANIFEST)) from None


def dotted(data: object, path: str) -> object:
    """The value at ``path`` (keys joined by dots, list items by index) of a Result's JSON, or None."""
    node = data
    for key in path.split("."):
        if isinstance(node, dict) and key in node:
            node = node[key]
        elif isinstance(node, list) and key.isdigit() and int(key) < len(node):
            node = node[int(key)]
        else:
            return None
    return node


def read_metric(data: dict, path: str) -> float | None:
    """The number at ``path`` of a Result's JSON (a flag as 0 or 1), or None."""
    node = dotted(data, path)
    if isinstance(node, bool):
        return float(node)
    return float(node) if isinstance(node, int | float) else None


def verdict(experiment: Experiment, value: float | None, values: dict[str, float | None]) -> str:
    """``holds``, ``differs``, ``withheld`` (nothing to compare) or ``failed`` (no value)."""
    if value is None or not math.isfinite(value):
        return "failed"
    tests = []
    if isinstance(experiment.thesis, float):
        tests.append(abs(value - experiment.thesis) <= experiment.tolerance)
    for other, sign in ((experiment.above, 1.0), (experiment.below, -1.0)):
        if other is not None:
            them = values.get(other) if isinstance(other, str) else other
            tests.append(them is not None and sign * (value - them) > 0)
    if not tests:
        return "withheld" if experiment.thesis == "withheld" else "no thesis value"
    return "holds" if all(tests) else "differs"


def _number(value: float | None) -> str:
    return "—" if value is None else f"{value:.6g}"


def thesis_cell(experiment: Experiment) -> str:
    """What the thesis says: its number (± the tolerance), 'withheld', and its stated ordering."""
    parts = []
    if isinstance(experiment.thesis, float):
        parts.append(f"{experiment.thesis:.6g} (± {experiment.tolerance:g})")
    elif experiment.thesis == "withheld":
        parts.append("withheld")
    if experiment.statement:
        parts.append(experiment.statement)
    return "; ".join(parts) or "—"


def table_rows(
    experiments: list[Experiment], values: dict[str, float | None], statuses: dict[str, str]
) -> list[dict[str, str]]:
    """One row per experiment: the COLUMNS as text. ``statuses`` holds, per row, the status of its
    Result where it is not ``optimal`` (shown beside the value), or why there is no Result."""
    rows = []
    for e in experiments:
        value = values.get(e.name)
        outcome = verdict(e, value, values)
        status = statuses.get(e.name, "")
        reason = e.reason or ""
        if outcome == "failed":
            reason = status or f"no number at {e.metric}"
        elif outcome == "differs" and not reason:
            reason = "no reason recorded"
        shown = _number(value) + (f" ({status})" if status and value is not None else "")
        rows.append(
            {
                "experiment": e.title,
                "file": " ".join(
                    [e.file, *(f"--set {s}" for s in e.set), *(["--backend", e.backend] if e.backend else [])]
                ),
                "reference": e.reference,
                "thesis": thesis_cell(e),
                "gamespec": shown,
                "verdict": outcome,
                "reason": reason,
            }
        )
    return rows


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def write_markdown(rows: list[dict[str, str]], path: Path) -> Path:
    """The table as a Markdown page."""
    lines = ["| " + " | ".join(COLUMNS) + " |", "|" + "---|" * len(COLUMNS)]
    lines += ["| " + " | ".join(_cell(row[c]) for c in COLUMNS) + " |" for row in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def write_csv(rows: list[dict[str, str]], path: Path) -> Path:
    """The table as CSV, one header line."""
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    return path
