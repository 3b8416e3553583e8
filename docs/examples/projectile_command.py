"""A new command: ``gamespec projectile range SPEED ANGLE``. A command is a Typer app registered in
the ``gamespec.commands`` group; ``gamespec`` mounts it under its name."""

from __future__ import annotations

from typing import Annotated

import typer

from gamespec import registry, solve, spec_from_dict

projectile_app = typer.Typer(no_args_is_help=True, help="Projectile examples.")


@projectile_app.command("range")
def range_(
    speed: Annotated[float, typer.Argument(help="Launch speed.")],
    angle: Annotated[float, typer.Argument(help="Launch angle, degrees.")],
) -> None:
    """Print the range of a projectile (solved on its default backend)."""
    result = solve(spec_from_dict({"kind": "projectile", "speed": speed, "angle": angle}))
    typer.echo(f"range {result.metrics['range']:.6g} ({result.status.value} on {result.backend})")


registry.register("gamespec.commands", "projectile", projectile_app)
