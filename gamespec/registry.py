"""Lazy plugin registries read from entry points (after pluggy's ``_importlib_metadata``).

Groups: ``gamespec.kinds`` (spec classes by ``kind``), ``gamespec.backends`` (backend classes by
name), ``gamespec.transforms`` (spec → spec reductions), ``gamespec.plotters`` (plot functions by
kind), ``gamespec.executors`` (how a study runs its points) and ``gamespec.commands`` (Typer apps
of area commands, by sub-command name). Nothing is imported until it is asked for, so
``import gamespec`` stays light.
"""

from __future__ import annotations

from functools import cache
from importlib.metadata import EntryPoint, entry_points
from typing import Any

from gamespec.errors import BackendError, SpecError

GROUPS = (
    "gamespec.kinds",
    "gamespec.backends",
    "gamespec.transforms",
    "gamespec.plotters",
    "gamespec.executors",
    "gamespec.commands",
)


@cache
def _entry_points(group: str) -> dict[str, EntryPoint]:
    return {ep.name: ep for ep in entry_points(group=group)}


def names(group: str) -> list[str]:
    """Names registered in ``group``, sorted."""
    return sorted(_entry_points(group))


def distribution(group: str, name: str) -> str:
    """The distribution (and version) that registered ``name`` in ``group``."""
    ep = _entry_points(group)[name]
    dist = ep.dist
    return f"{dist.name} {dist.version}" if dist is not None else "?"


@cache
def load(group: str, name: str) -> Any:
    """Import and return the object registered as ``name`` in ``group``."""
    try:
        ep = _entry_points(group)[name]
    except KeyError:
        known = ", ".join(names(group)) or "none"
        if group == "gamespec.kinds":
            raise SpecError(f"unknown kind {name!r} (known: {known})", field="kind") from None
        raise BackendError(f"unknown {group.split('.')[1][:-1]} {name!r} (known: {known})") from None
    return ep.load()


def spec_class(kind: str) -> type:
    """The spec model registered for ``kind``."""
    return load("gamespec.kinds", kind)


def backend_class(name: str) -> type:
    """The backend class registered as ``name``."""
    return load("gamespec.backends", name)
