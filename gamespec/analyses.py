"""Analyses: what is computed *about* a solution, declared, chosen and cached (DESIGN.md, stage 4).

An :class:`Analysis` is a named computation on a mapped-back Result that never solves: a Monte
Carlo re-simulation (§6.3.1), an LQR-tracking closed loop (eqs. 6.27-6.29), the re-simulation of an
engagement under its heading (eq. 2.1). It declares the analyses it ``needs`` (run first, their
outputs in the Result it gets) and the ``checks`` it decides: the checks of the status
(:func:`gamespec.solving.status_policy`, a transform's ``verify``) that its outputs are the only
evidence for. Its :attr:`~Analysis.run` returns :class:`Outputs`, the ``metrics``, ``checks`` and
``arrays`` entries it writes, merged into the Result by :func:`run_analyses`.

Who declares them:

- a transform, in :meth:`gamespec.transforms.base.Transform.analyses`; they run on the Result that
  transform's ``invert`` returns, with its source spec and inverse data;
- a kind, in the ``gamespec.analyses`` entry-point group (name: the kind; object: a sequence of
  analyses); they run on every Result of that kind along the chain (the compiled model's, and
  each one a transform maps back), with its spec and no inverse data.

A :data:`Selection` picks among them: ``"all"`` (the default for ``solve``), ``"none"``, or a list
of names (each closed over its ``needs``). A name no installed transform or kind declares is a
SpecError listing the known ones (:func:`check_names`). A selected analysis that does not belong to
the chain being solved runs nowhere (a study passes its choice on to the chains of its points).

A skipped analysis that decides a check leaves the check unmade: :func:`run_analyses` records it
in ``metrics["checks_skipped"]`` with the reason :data:`SKIPPED`, and the solving layer does not
claim ``optimal`` for it (``docs/statuses.md``).

Outputs are cached (:class:`AnalysisCache`) by the analysis, the hash of the spec it ran for (its
``analyses:`` key left out) and the solution it ran on (to :data:`AGREEMENT`), so a repeated solve
of the same problem never re-runs a Monte Carlo; a plot reads the saved Result and runs nothing.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel

from gamespec import registry
from gamespec.errors import SpecError
from gamespec.result import Result
from gamespec.specs.hashing import spec_hash

Selection = Literal["all", "none"] | list[str]
"""Which analyses run: all of them, none, or those named (with what they need)."""

SKIPPED = "analyses off"
"""The reason ``metrics["checks_skipped"]`` gives for a check whose analysis was not selected."""


@dataclass(frozen=True)
class Outputs:
    """What an analysis writes into a Result: entries of its ``metrics``, ``checks`` and ``arrays``
    (a key already there is replaced)."""

    metrics: dict[str, Any] = field(default_factory=dict)
    checks: dict[str, float | None] = field(default_factory=dict)
    arrays: dict[str, np.ndarray] = field(default_factory=dict)

    def merged(self, result: Result) -> Result:
        """``result`` with these entries written in."""
        return result.model_copy(
            update={
                "metrics": {**result.metrics, **self.metrics},
                "checks": {**result.checks, **self.checks},
                "arrays": {**result.arrays, **self.arrays},
            }
        )


Run = Callable[[Result, Any, Any], Outputs]
"""``run(result, spec, inverse_data) -> Outputs``: pure, never solves; it gets only usable
Results (``result.ok``)."""


@dataclass(frozen=True)
class Analysis:
    """One declared analysis (see module doc)."""

    name: str
    run: Run
    description: str
    needs: tuple[str, ...] = ()
    """Analyses of the same declarer that must run first."""
    checks: tuple[str, ...] = ()
    """The checks of the status it decides (``result.checks`` names)."""


def kind_analyses(kind: str) -> list[Analysis]:
    """The analyses the kind ``kind`` declares (its :class:`~gamespec.registry.Kind`'s
    ``analyses``; none when it declares none or is not installed)."""
    return list(registry.kind_part(kind, "analyses") or [])


def known_names() -> list[str]:
    """Every analysis name an installed transform or kind declares, sorted."""
    names = {a.name for kind in registry.names("gamespec.kinds") for a in kind_analyses(kind)}
    for name in registry.names("gamespec.transforms"):
        names |= {a.name for a in registry.load("gamespec.transforms", name)().analyses()}
    return sorted(names)


def unknown(names: Sequence[str]) -> str | None:
    """What is wrong with ``names`` when one is no installed transform's or kind's analysis (the
    known names listed), None when every one is known."""
    known = known_names()
    missing = [name for name in names if name not in known]
    if not missing:
        return None
    listed = ", ".join(known) or "none"
    return f"unknown analysis {', '.join(map(repr, missing))} (known: {listed}; or all, none)"


def check_names(selection: Selection, source: str = "<spec>", field_name: str = "analyses") -> None:
    """A SpecError naming ``field_name`` when ``selection`` names an unknown analysis (:func:`unknown`)."""
    reason = None if isinstance(selection, str) else unknown(selection)
    if reason is not None:
        raise SpecError(reason, field=field_name, source=source)


def parse_selection(text: str) -> Selection:
    """``--analyses`` as given on the command line: ``all``, ``none`` or ``NAME,NAME,...``."""
    if text.strip() in ("all", "none"):
        return text.strip()  # type: ignore[return-value]
    names = [part.strip() for part in text.split(",") if part.strip()]
    if not names:
        raise SpecError("give all, none or NAME[,NAME...]", field="--analyses", source="<command line>")
    return names


def as_override(text: str) -> str:
    """``--analyses TEXT`` as the ``--set`` assignment of the file's ``analyses:`` key (so it is
    validated, hashed and carried to a study's or a sweep's workers like any other field)."""
    chosen = parse_selection(text)
    return f"analyses={chosen if isinstance(chosen, str) else '[' + ', '.join(chosen) + ']'}"


def for_study(chosen: str | list[str] | None, needed: Sequence[str]) -> Selection:
    """The analyses a study's points run: the ``needed`` ones its table is made of, and those the
    study file (or ``--analyses``) chooses on top (``all``: every one; ``none`` or nothing: only
    the needed ones)."""
    if chosen == "all":
        return "all"
    extra = [] if chosen is None or chosen == "none" else list(chosen)
    return [*needed, *(name for name in extra if name not in needed)]


def selected(declared: Sequence[Analysis], selection: Selection) -> list[Analysis]:
    """The analyses of ``declared`` that ``selection`` picks, with those they need, in declared
    order."""
    if selection == "all":
        return list(declared)
    if selection == "none":
        return []
    by_name = {a.name: a for a in declared}
    wanted: set[str] = set()
    pending = [name for name in selection if name in by_name]
    while pending:
        name = pending.pop()
        if name not in wanted:
            wanted.add(name)
            pending.extend(n for n in by_name[name].needs if n in by_name)
    return [a for a in declared if a.name in wanted]


def skipped_checks(declared: Sequence[Analysis], selection: Selection) -> list[str]:
    """The checks that the analyses ``selection`` leaves out of ``declared`` decide."""
    chosen = {a.name for a in selected(declared, selection)}
    return [c for a in declared if a.name not in chosen for c in a.checks]


AGREEMENT = 1e-7
"""Two Results whose solutions (:func:`solution`) agree to this, relative to the largest entry,
count as the same for the cache: a warm-started re-solve of the same problem differs by about
1e-10, well inside any solver's tolerance, and an analysis of either says the same."""


def solution(result: Result) -> tuple[tuple[Any, ...], np.ndarray]:
    """What an analysis reads from a Result: its status and the names and shapes of its
    trajectories (compared exactly), and one vector of its objective, final time, parameters,
    time grids, states and controls (compared to :data:`AGREEMENT`). What analyses write is a
    function of these, so it is left out (and so are the checks)."""
    named = {"time": result.time, "control_time": result.control_time}
    named |= {f"state {k}": v for k, v in result.states.items()}
    named |= {f"control {k}": v for k, v in result.controls.items()}
    arrays = [(k, np.asarray(v, dtype=float).ravel()) for k, v in sorted(named.items()) if v is not None]
    scalars = [result.objective, result.t_final, *result.parameters.values()]
    vector = np.concatenate([[np.nan if v is None else v for v in scalars], *(a for _, a in arrays)])
    shape = (result.status.value, tuple(result.parameters), tuple((k, a.size) for k, a in arrays))
    return shape, vector


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    scale = float(np.max(np.abs(a[np.isfinite(a)]), initial=0.0)) or 1.0
    return bool(np.allclose(a, b, rtol=0.0, atol=AGREEMENT * scale, equal_nan=True))


class AnalysisCache:
    """The outputs of the last :attr:`size` analyses run, by analysis, spec hash and the solution
    they ran on (:func:`solution`); :attr:`runs` counts the analyses actually run (not found here)."""

    def __init__(self, size: int = 128) -> None:
        self.size = size
        self.runs = 0
        self._outputs: OrderedDict[int, tuple[tuple[Any, ...], np.ndarray, Outputs]] = OrderedDict()
        self._count = 0

    def outputs(self, analysis: Analysis, spec_key: str, result: Result, spec: Any, inverse: Any) -> Outputs:
        """The outputs of ``analysis`` on ``result``: from the cache, or run and kept."""
        shape, vector = solution(result)
        key = (analysis.name, spec_key, shape)
        for entry, (known, seen, found) in self._outputs.items():
            if known == key and _same(seen, vector):
                self._outputs.move_to_end(entry)
                return found
        self.runs += 1
        found = analysis.run(result, spec, inverse)
        self._count += 1
        self._outputs[self._count] = (key, vector, found)
        if len(self._outputs) > self.size:
            self._outputs.popitem(last=False)
        return found

    def clear(self) -> None:
        """Forget every kept output."""
        self._outputs.clear()


CACHE = AnalysisCache()
"""The process's cache of analysis outputs (the solving layer's)."""


def run_analyses(
    result: Result,
    declared: Sequence[Analysis],
    selection: Selection,
    spec: Any,
    inverse: Any = None,
    options: BaseModel | None = None,
    cache: AnalysisCache = CACHE,
) -> Result:
    """``result`` with the outputs of the analyses of ``declared`` that ``selection`` picks (on a
    usable Result only), and ``metrics["checks_skipped"]`` naming each check the others decide.
    The cache knows the problem by the hash of ``spec`` without its ``analyses:`` choice and the
    declaring transform's ``options``."""
    if not declared or not result.ok:
        return result
    chosen = selected(declared, selection)
    key = ""
    if chosen:
        key = spec_hash(spec if spec.analyses is None else spec.model_copy(update={"analyses": None}))
        key += "" if options is None else options.model_dump_json()
    for analysis in chosen:
        result = cache.outputs(analysis, key, result, spec, inverse).merged(result)
    skipped = skipped_checks(declared, selection)
    if skipped:
        notes = {**result.metrics.get("checks_skipped", {}), **dict.fromkeys(skipped, SKIPPED)}
        result = result.model_copy(update={"metrics": {**result.metrics, "checks_skipped": notes}})
    return result
