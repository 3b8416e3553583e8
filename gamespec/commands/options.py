"""Options shared by the core commands and the area commands (``gamespec pursuit study``)."""

from __future__ import annotations

from typing import Annotated

import typer

AnalysesOpt = Annotated[
    str | None,
    typer.Option(
        "--analyses",
        help="Analyses of the solution to run: all (the default), none, or NAME,NAME (e.g. "
        "monte_carlo,lqr_tracking,resimulation); the file's analyses: key.",
    ),
]


def with_analyses(set_: list[str] | None, analyses: str | None) -> list[str]:
    """The ``--set`` overrides, with ``--analyses`` as the file's ``analyses:`` key."""
    if analyses is None:
        return list(set_ or [])
    from gamespec.analyses import as_override

    return [*(set_ or []), as_override(analyses)]
