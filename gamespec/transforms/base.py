"""Spec → spec transforms after cvxpy's ``Reduction``: ``accepts``, ``apply``, ``invert``.

A transform maps a spec of ``source_kind`` to one of ``target_kind`` and remembers (its inverse
data) what it needs to map a Result of the new spec back to the names the user wrote. It is pure:
:meth:`Transform.apply` and :meth:`Transform.invert` never solve and never pick a backend. What
needs solving is asked of the solving layer (:mod:`gamespec.solving`):

- a **staged** transform names, in :meth:`Transform.stage`, a spec to solve first; the solving layer
  solves it and passes its Result to ``apply(..., upstream=result)``;
- a transform whose mapped-back Result can fail a check of the source problem says so in
  :meth:`Transform.verify` and offers other starting points in :meth:`Transform.restarts`; the
  solving layer re-solves the same compiled model from them (multi-start) when the check fails or
  the solve does, and keeps the best verified Result;
- what is computed *about* a mapped-back Result (a Monte Carlo, a re-simulation, LQR tracking) is
  not ``invert``'s: a transform declares it in :meth:`Transform.analyses`
  (:mod:`gamespec.analyses`), and the solving layer runs the selected ones after ``invert`` and
  before ``verify``.

Runtime parameters go through the chain as in cvxpy's ``apply_parameters``: cvxpy canonicalizes a
parametrized problem once (its reductions keep the structure and the inverse data) and, for new
parameter values, only maps them through the cached parametrized program to the solver's data. Here
:meth:`Transform.parameter_map` maps the source's runtime parameter values to the target's and
refreshes the inverse data, without re-applying the transform; the solving layer hands the compiled
model the last target's values. A transform maps the parameters it can map cheaply; those in
:meth:`Transform.unmapped` (by default all of them: a transform without a map is always correct)
make the solving layer re-apply it, and every later step, and check that the target's
:meth:`~SpecBase.structure` did not change.

*Requested* transforms (``requested = True``: same kind to same kind, applied when a file lists them
under ``transforms:``, with options validated by ``options_model``) come first, in the file's
order; then *lowering* transforms, found by kind (:func:`lowering_path`). Transforms register in
the ``gamespec.transforms`` entry-point group under their ``name``. A transform owns the figures and
summary rows of what it adds to a Result (``plot``, ``summary``: ``"module:function"`` texts, imported
when a Result that went through it is plotted or summarized; :func:`gamespec.registry.transform_parts`).

:class:`Transform` is generic in its source spec class, its target spec class, its options model and
its inverse data (``Transform[EngagementSpec, OptimalControlSpec, NoOptions, EngagementInverse]``),
so each plugin's ``apply``/``invert``/``verify``/``restarts``/``parameter_map`` are typed with its
own classes and mypy checks them against the contract; :meth:`Transform.accepts` is the run-time
check that lets a spec of the chain (a :class:`SpecBase`) in as ``Src``.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Generic, TypeGuard, TypeVar, cast

from pydantic import BaseModel

from gamespec import registry
from gamespec.analyses import Analysis
from gamespec.compiling import NoOptions
from gamespec.result import Result
from gamespec.specs.base import SpecBase, SpecT, StrictModel
from gamespec.specs.requested import entry, transform_class, validated_options

if TYPE_CHECKING:
    # Named by a string in OcpRewrite's base: importing the OCP kind at run time would cost the
    # solving chain's import 0.1 s, and a lowering chain may never need it.
    from gamespec.specs.ocp import OptimalControlSpec  # noqa: F401


@dataclass(frozen=True)
class Stage:
    """An upstream solve a staged transform needs: ``spec`` on ``backend`` (None: the caller's
    backend, with its options, where it solves ``spec``'s kind, else that kind's default)."""

    spec: SpecBase
    backend: str | None = None


Src = TypeVar("Src", bound=SpecBase)
"""The spec class a transform takes (the class of its ``source_kind``)."""

Dst = TypeVar("Dst", bound=SpecBase)
"""The spec class a transform returns (the class of its ``target_kind``)."""

Options = TypeVar("Options", bound=StrictModel)
"""The options model of a transform (:class:`~gamespec.compiling.NoOptions` for one that takes none)."""

Inverse = TypeVar("Inverse")
"""The inverse data :meth:`Transform.apply` returns and the other methods receive."""


class Transform(ABC, Generic[Src, Dst, Options, Inverse]):
    """One reduction step (see module doc)."""

    name: ClassVar[str]
    source_kind: ClassVar[str]
    target_kind: ClassVar[str]
    requested: ClassVar[bool] = False
    options_model: type[Options] = cast("type[Options]", NoOptions)
    """The model of the options; a transform that takes options sets it to the class it is
    parameterized with (mypy checks that), one that takes none keeps ``NoOptions``."""
    plot: ClassVar[str | None] = None
    """``"module:function"``: ``plot(result, output_dir) -> list[Path]``, the figures of what this
    transform adds to a Result (None: none)."""
    summary: ClassVar[str | None] = None
    """``"module:function"``: ``summary(result) -> list[(label, value)]``, its rows in ``gamespec
    solve``'s table (None: none)."""

    def accepts(self, spec: SpecBase) -> TypeGuard[Src]:
        """Whether this transform applies to ``spec`` (by default: any spec of ``source_kind``,
        which is of class ``Src``: the registry maps a kind to one spec class). An override returns
        ``TypeGuard[...]`` of its ``Src`` too, and asks ``super().accepts(spec)`` first."""
        return spec.kind == self.source_kind

    def stage(self, spec: Src, options: Options) -> Stage | None:
        """The upstream solve :meth:`apply` needs the Result of, or None (the default)."""
        return None

    @abstractmethod
    def apply(self, spec: Src, options: Options, upstream: Result | None = None) -> tuple[Dst, Inverse]:
        """The new spec and the data :meth:`invert` needs; ``upstream`` is the Result of
        :meth:`stage`'s spec when it names one, whatever its status (check ``upstream.ok``)."""

    def invert(self, result: Result, spec: Src, inverse_data: Inverse) -> Result:
        """Map a Result of the transformed spec back to the original ``spec`` (default: relabel);
        names only, never an analysis (:meth:`analyses`)."""
        return result.model_copy(update={"kind": spec.kind, "problem": spec.name})

    def analyses(self) -> list[Analysis]:
        """The analyses of a Result :meth:`invert` returns, run (when selected) with ``spec`` and the
        inverse data before :meth:`verify`, in this order (the default: none)."""
        return []

    def guess(self, inverse_data: Inverse) -> Result | None:
        """A starting point of the target spec (a Result in its names) the solving layer passes to
        the compiled model when the caller gives none; None (the default) leaves it to the model."""
        return None

    def verify(self, result: Result, spec: Src, inverse_data: Inverse) -> str | None:
        """The first check of the source problem a mapped-back ``result`` fails, or None when it
        passes (the default: nothing to check)."""
        return None

    def restarts(self, spec: Src, inverse_data: Inverse) -> list[Result]:
        """Other starting points of the target spec, best first, to re-solve from when
        :meth:`verify` fails or the solve itself does not succeed (the default: none)."""
        return []

    def unmapped(self, spec: Src) -> frozenset[str]:
        """The runtime parameters of ``spec`` that :meth:`parameter_map` cannot map: a new value of
        one of them makes the solving layer re-apply this transform (the default: all of them)."""
        return frozenset(spec.runtime_parameters())

    def parameter_map(self, spec: Src, inverse_data: Inverse) -> tuple[dict[str, float], Inverse]:
        """The target's runtime parameter values and the inverse data for ``spec``, the compiled
        source with new values of runtime parameters outside :meth:`unmapped` (the same structure),
        as :meth:`apply` would give them, but cheaply (cvxpy's ``apply_parameters``).
        ``inverse_data`` is the compiled step's. Called only when :meth:`unmapped` leaves room."""
        raise NotImplementedError(f"transform {self.name!r} has no parameter map")


def with_parameter_values(spec: SpecT, values: Mapping[str, float]) -> SpecT:
    """``spec`` with its runtime parameters (by :meth:`~SpecBase.runtime_parameters`' names) set to
    ``values``, copied without re-validation: for a parameter map's target, whose values the
    validated source determines (every other field, its source and file hash kept). Each model
    on the way is copied once, however many of its parameters change."""
    return with_field_values(spec, {spec.parameter_path(n): v for n, v in values.items()})


def with_field_values(spec: SpecT, values: Mapping[str, Any]) -> SpecT:
    """``spec`` with the fields at the dotted paths of ``values`` set to them, copied without
    re-validation (as :func:`with_parameter_values`)."""
    tree: dict[str, Any] = {}
    for path, value in values.items():
        *parents, last = path.split(".")
        node = tree
        for part in parents:
            node = node.setdefault(part, {})
        node[last] = _Set(value)
    updated: SpecT = _updated(spec, tree)
    return updated


@dataclass(frozen=True)
class _Set:
    """A leaf of :func:`with_parameter_values`' tree of changes: the new value."""

    value: Any


def _updated(node: Any, changes: dict[str, Any] | _Set) -> Any:
    """A copy of ``node`` with ``changes`` (a tree by field name, key or index) applied."""
    if isinstance(changes, _Set):
        return changes.value
    if isinstance(node, BaseModel):
        return node.model_copy(update={k: _updated(getattr(node, k), c) for k, c in changes.items()})
    if isinstance(node, dict):
        return {**node, **{k: _updated(node[k], c) for k, c in changes.items()}}
    items = list(node)
    for key, change in changes.items():
        items[int(key)] = _updated(items[int(key)], change)
    return type(node)(items)


AnyTransform = Transform[Any, Any, Any, Any]
"""A transform of the chain, its classes known only at run time (found by name or kind)."""


def _lowering() -> list[AnyTransform]:
    found: list[AnyTransform] = []
    for name in registry.names("gamespec.transforms"):
        cls = registry.load("gamespec.transforms", name)
        if not cls.requested:
            found.append(cls())
    return found


def requested_steps(spec: SpecBase) -> list[tuple[AnyTransform, StrictModel]]:
    """The transforms ``spec``'s ``transforms:`` section asks for, with their validated options."""
    steps: list[tuple[AnyTransform, StrictModel]] = []
    for index, item in enumerate(spec.transforms):
        name, options = entry(item, index)
        cls = transform_class(name, field=f"transforms.{index}")
        steps.append((cls(), validated_options(cls, name, options, index)))
    return steps


def lowering_path(spec: SpecBase, kinds: frozenset[str]) -> list[AnyTransform] | None:
    """The shortest chain of lowering transforms taking ``spec`` to one of ``kinds`` (``[]`` if it
    is one already), its first step one that :meth:`~Transform.accepts` ``spec``; None if none."""
    if spec.kind in kinds:
        return []
    available = _lowering()
    queue: deque[tuple[str, list[AnyTransform]]] = deque([(spec.kind, [])])
    seen = {spec.kind}
    while queue:
        kind, path = queue.popleft()
        for t in available:
            if t.source_kind != kind or t.target_kind in seen or (not path and not t.accepts(spec)):
                continue
            if t.target_kind in kinds:
                return [*path, t]
            seen.add(t.target_kind)
            queue.append((t.target_kind, [*path, t]))
    return None


class KeepsParameters(Generic[Src, Inverse]):
    """Mixin of a transform whose target has exactly the source's runtime parameters (what it
    generates keeps them as symbols) and whose inverse data holds no value of theirs: every
    parameter maps, to itself, and the inverse data stays as it is. Parameterized with the
    transform's ``Src`` and ``Inverse``, so that its methods are the transform's."""

    def unmapped(self, spec: Src) -> frozenset[str]:
        return frozenset()

    def parameter_map(self, spec: Src, inverse_data: Inverse) -> tuple[dict[str, float], Inverse]:
        return spec.runtime_parameters(), inverse_data


class OcpRewrite(Transform["OptimalControlSpec", "OptimalControlSpec", Options, Inverse], ABC):
    """A requested ``optimal_control`` → ``optimal_control`` rewrite (chapter 6's desensitization
    and regularizers): applied only when a file's ``transforms:`` list names it."""

    source_kind: ClassVar[str] = "optimal_control"
    target_kind: ClassVar[str] = "optimal_control"
    requested: ClassVar[bool] = True
