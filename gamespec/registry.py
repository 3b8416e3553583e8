"""Lazy plugin registries read from entry points (after pluggy's ``_importlib_metadata``).

Groups: ``gamespec.kinds`` (spec classes by ``kind``), ``gamespec.backends`` (backend classes by
name), ``gamespec.transforms`` (spec → spec reductions), ``gamespec.plotters`` (plot functions by
kind), ``gamespec.summaries`` (the rows that lead a kind's solve summary), ``gamespec.metrics``
(the typed metrics of a kind's Results), ``gamespec.executors``
(how a study runs its points) and ``gamespec.commands`` (Typer apps mounted as ``gamespec NAME``).
Nothing is imported until it is asked for, so ``import gamespec`` stays light; the installed
distributions' entry points are read in one pass, the first time any group is asked for.
"""

from __future__ import annotations

import sys
from functools import cache
from importlib.metadata import EntryPoint, entry_points
from typing import Any

from gamespec.errors import BackendError, SpecError

if sys.version_info >= (3, 12):
    from importlib.metadata import EntryPoints as _AllEntryPoints
else:  # entry_points() is a SelectableGroups (with .select) before 3.12
    from importlib.metadata import SelectableGroups as _AllEntryPoints

GROUPS = (
    "gamespec.kinds",
    "gamespec.backends",
    "gamespec.transforms",
    "gamespec.plotters",
    "gamespec.summaries",
    "gamespec.metrics",
    "gamespec.executors",
    "gamespec.commands",
)


_IN_PROCESS: dict[str, dict[str, Any]] = {group: {} for group in GROUPS}
"""Objects registered with :func:`register` (scripts, notebooks, tests), ahead of entry points."""


@cache
def _installed() -> _AllEntryPoints:
    """Every installed distribution's entry points (one pass over their metadata; a pass per group
    would read all of it again for each)."""
    return entry_points()


@cache
def _entry_points(group: str) -> dict[str, EntryPoint]:
    return {ep.name: ep for ep in _installed().select(group=group)}


def register(group: str, name: str, obj: Any) -> None:
    """Register ``obj`` as ``name`` in ``group`` for this process, as an entry point of an installed
    package would (which is how a plugin ships: see the docs, "Extending gamespec")."""
    if group not in _IN_PROCESS:
        raise BackendError(f"unknown plugin group {group!r} (known: {', '.join(GROUPS)})")
    _IN_PROCESS[group][name] = obj
    load.cache_clear()


def names(group: str) -> list[str]:
    """Names registered in ``group``, sorted."""
    return sorted({*_entry_points(group), *_IN_PROCESS.get(group, {})})


def distribution(group: str, name: str) -> str:
    """The distribution (and version) that registered ``name`` in ``group``."""
    if name in _IN_PROCESS.get(group, {}):
        return "registered in this process"
    return _installed_distribution(group, name)


@cache
def _installed_distribution(group: str, name: str) -> str:
    """An entry point's distribution and version, read once: reading a distribution's version
    parses its metadata file, and every Result's provenance asks for it."""
    dist = _entry_points(group)[name].dist
    return f"{dist.name} {dist.version}" if dist is not None else "?"


@cache
def load(group: str, name: str) -> Any:
    """Import and return the object registered as ``name`` in ``group``."""
    if name in _IN_PROCESS.get(group, {}):
        return _IN_PROCESS[group][name]
    try:
        ep = _entry_points(group)[name]
    except KeyError:
        known = ", ".join(names(group)) or "none"
        if group == "gamespec.kinds":
            raise SpecError(f"unknown kind {name!r} (known: {known})", field="kind") from None
        raise BackendError(f"unknown {group.split('.')[1][:-1]} {name!r} (known: {known})") from None
    return ep.load()


def spec_class(kind: str) -> Any:
    """The spec model registered for ``kind`` (a :class:`~gamespec.specs.base.SpecBase` subclass;
    typed by the caller, this layer knows no spec)."""
    return load("gamespec.kinds", kind)


def backend_class(name: str) -> Any:
    """The backend class registered as ``name`` (a :class:`~gamespec.backend.Backend` subclass;
    typed by the caller, this layer knows no backend)."""
    return load("gamespec.backends", name)
