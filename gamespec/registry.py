"""Lazy plugin registries read from entry points (after pluggy's ``_importlib_metadata``).

Groups: ``gamespec.kinds`` (one :class:`Kind` per problem kind: a kind is one plugin),
``gamespec.backends`` (backend classes by name), ``gamespec.studies`` (the
:class:`~gamespec.compiling.study_protocol.Study` plugins that run a study kind's many solves),
``gamespec.transforms`` (spec →
spec reductions, each owning its plot and summary rows), ``gamespec.executors`` (how a study runs
its points) and ``gamespec.commands`` (Typer apps mounted as ``gamespec NAME``). Nothing is
imported until it is asked for, so ``import gamespec`` stays light; the installed distributions'
entry points are read in one pass, the first time any group is asked for.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from functools import cache
from importlib import import_module
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
    "gamespec.studies",
    "gamespec.transforms",
    "gamespec.executors",
    "gamespec.commands",
)

Ref = Any
"""An object, or the ``"module:attribute"`` text that names it (imported only when asked for, so
that declaring a kind does not import its plotter)."""


def resolved(ref: Ref) -> Any:
    """``ref`` itself, or the object its ``"module:attribute"`` text names."""
    if not isinstance(ref, str):
        return ref
    module, _, attribute = ref.partition(":")
    return getattr(import_module(module), attribute)


@dataclass(frozen=True)
class Kind:
    """One problem kind, everything about it in one entry point of ``gamespec.kinds``
    (``docs/architecture.md``: a kind is one plugin).

    ``spec`` is its pydantic model (a :class:`~gamespec.specs.base.SpecBase` with a ``kind``
    literal); ``default_backend`` the backend that solves it when a file names none, or, for a study
    kind, ``study`` the :class:`~gamespec.compiling.study_protocol.Study` plugin that runs it
    (exactly one of the two); ``plot`` its plotter ``(result, output_dir, *, animate) ->
    list[Path]``, ``summary`` its rows ``(result) -> list[(label, value)]`` that lead ``gamespec
    solve``'s table, ``metrics`` the :class:`~gamespec.metrics.Metrics` model of its Results'
    ``metrics`` (None: the common one), ``analyses`` the list of
    :class:`~gamespec.analyses.Analysis` its Results get (:mod:`gamespec.analyses`; None: none),
    ``columns`` its headline numbers as a study table's columns (the dotted names
    :func:`gamespec.studies.export.study_rows` gives them, ``metrics.capture_time``), shown by
    ``gamespec results`` after the swept parameters where the study's points have them.
    The parts other than ``spec`` and ``columns`` may be ``"module:attribute"`` texts, imported
    when first used.
    """

    spec: Ref
    default_backend: str | None = None
    study: str | None = None
    plot: Ref | None = None
    summary: Ref | None = None
    metrics: Ref | None = None
    analyses: Ref | None = None
    columns: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if (self.default_backend is None) == (self.study is None):
            raise BackendError("a kind names either a default backend or the study that runs it")

    def part(self, name: str) -> Any:
        """The kind's ``spec``, ``plot``, ``summary``, ``metrics`` or ``analyses``, imported (None
        if it has none)."""
        ref = getattr(self, name)
        return None if ref is None else resolved(ref)


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


def kind(name: str) -> Kind:
    """The :class:`Kind` registered as ``name`` (a SpecError naming the ``kind`` field if none is)."""
    found: Kind = load("gamespec.kinds", name)
    return found


def kind_part(name: str, part: str) -> Any:
    """The ``part`` of kind ``name`` (:meth:`Kind.part`), None when no kind ``name`` is installed (a
    Result read from a folder may name one that is not)."""
    return kind(name).part(part) if name in names("gamespec.kinds") else None


def spec_class(name: str) -> Any:
    """The spec model of kind ``name`` (a :class:`~gamespec.specs.base.SpecBase` subclass; typed by
    the caller, this layer knows no spec)."""
    return kind(name).part("spec")


def backend_class(name: str) -> Any:
    """The backend class registered as ``name`` (a :class:`~gamespec.compiling.Backend` subclass;
    typed by the caller, this layer knows no backend)."""
    return load("gamespec.backends", name)


RUNNERS = ("gamespec.backends", "gamespec.studies")
"""What ``solver.backend``, ``solver.options.<name>`` and ``--backend`` may name: a backend, or the
study that runs a study kind."""


def runner_names() -> list[str]:
    """The installed backends and studies, sorted."""
    return sorted({name for group in RUNNERS for name in names(group)})


def runner_group(name: str) -> str:
    """``gamespec.studies`` when ``name`` is a study, else ``gamespec.backends``."""
    return "gamespec.studies" if name in names("gamespec.studies") else "gamespec.backends"


def runner_class(name: str) -> Any:
    """The study or backend class registered as ``name`` (a BackendError naming both if neither; a
    :class:`~gamespec.compiling.study_protocol.Study` or :class:`~gamespec.compiling.Backend`
    subclass, typed by the caller)."""
    group = runner_group(name)
    if group == "gamespec.backends" and name not in names(group):
        raise BackendError(f"unknown backend {name!r} (known: {', '.join(runner_names())})")
    return load(group, name)


def transform_parts(transforms: list[str], part: str) -> list[Any]:
    """The ``plot`` or ``summary`` of each of ``transforms`` (the names a Result's chain applied,
    ``result.provenance.transforms``) that is installed and declares one, in order, imported: a
    transform owns its figures and summary rows, so a kind's plotter and summary need not know
    which transforms ran."""
    installed = names("gamespec.transforms")
    refs = [getattr(load("gamespec.transforms", name), part) for name in transforms if name in installed]
    return [resolved(ref) for ref in refs if ref is not None]
