"""The solving chain: spec → requested → lowering transforms → backend model → Result (DESIGN.md,
stages 2–4).

:func:`compile_spec` picks the backend, applies the transforms the file requests (in its order) and
then the lowering transforms that take the spec to a kind the backend solves, solving first the
upstream stage of any staged transform; it compiles the target once and returns a :class:`Solver`.

:meth:`Solver.solve` takes runtime parameters by the **source** spec's names (every field a user
can see, by dotted path, and a kind's short names such as an ``optimal_control`` parameter): it sets
them as ``--set`` would and re-validates the source spec, maps the new values through each step's
parameter map to the target's (cvxpy's ``apply_parameters``: no transform re-applied), and re-solves
the compiled model with the target's values. Only what the maps cannot take re-applies transforms
(:meth:`Solver.mapped_steps`): a parameter a transform lists as unmapped, a staged step, or a
dotted field that is no runtime parameter; the re-applied chain must then end in the compiled
target's structure, else a SpecError naming the parameters (the design's choice: a structural
change is a new compile, which the caller asks for with :func:`compile_spec`). When the
last transform's :meth:`~gamespec.transforms.base.Transform.verify` rejects the mapped-back Result,
or the solve fails, the same compiled model is re-solved from that transform's ``restarts``
(multi-start) with the caller's parameters and inputs, and the best verified Result is kept.

After each transform's ``invert``, and before its ``verify``, the solving layer runs the analyses
the transform declares that the Solver's selection picks, and a kind's analyses on every Result of
that kind along the chain (the compiled model's, each mapped-back one) (:mod:`gamespec.analyses`;
``analyses=`` of :func:`compile_spec`, else the file's ``analyses:`` key, else all). When a
skipped analysis decides a check (one ``verify`` reads), the Result is not verified: it is
``feasible``, not ``optimal``, and ``metrics["checks_skipped"]`` names the check
(``docs/statuses.md``).
"""

from __future__ import annotations

import datetime as _dt
import time
from dataclasses import dataclass, field, replace
from functools import cache, cached_property
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any, Generic, cast

from gamespec import registry
from gamespec.analyses import SKIPPED, Selection, check_names, kind_analyses, run_analyses, skipped_checks
from gamespec.compiling import Backend, CompiledModel, Inputs
from gamespec.compiling.study_protocol import Study
from gamespec.errors import BackendError, ExpressionError, SpecError, UnsupportedFeature, sourced
from gamespec.loader import load, with_values
from gamespec.result import Provenance, Result, Status
from gamespec.specs.base import SpecBase, StrictModel
from gamespec.specs.hashing import spec_hash
from gamespec.transforms.base import (
    AnyTransform,
    Dst,
    Inverse,
    Options,
    Src,
    Transform,
    lowering_path,
    requested_steps,
    with_field_values,
    with_parameter_values,
)

AnyBackend = Backend[Any, Any]
"""A backend chosen by name at run time: its spec and options classes are known only to itself
(:meth:`Backend.compile` checks the spec's kind before it reaches the typed ``_compile``)."""


def get_backend(name: str) -> AnyBackend:
    """An instance of the installed, available backend ``name``; BackendError with the reason else."""
    cls: type[AnyBackend] = registry.backend_class(name)
    availability = cls.available()
    if not availability.ok:
        raise BackendError(f"backend {name!r} is not available: {availability.reason}")
    return cls()


def backend_name(spec: SpecBase, backend: str | None = None) -> str:
    """The backend to use: the explicit one, the file's ``solver.backend``, or the kind's default."""
    name = backend or spec.solver.backend or spec.default_backend
    if not name:
        raise BackendError(f"no backend given and kind {spec.kind!r} has no default")
    return name


@cache
def _core_versions() -> dict[str, str]:
    found = {}
    for dist in ("gamespec", "numpy", "scipy", "sympy", "pydantic"):
        try:
            found[dist] = version(dist)
        except PackageNotFoundError:
            continue
    return found


def _versions(backend: AnyBackend | Study) -> dict[str, str]:
    return _core_versions() | {
        f"backend:{backend.name}": registry.distribution(registry.runner_group(backend.name), backend.name)
    }


@dataclass(frozen=True)
class Step(Generic[Src, Dst, Options, Inverse]):
    """One applied transform: ``source`` → ``target`` with ``options``; ``inverse`` is its inverse
    data and ``upstream`` the compiled upstream stage it took a Result from (None if not staged).
    Its classes are the transform's, so each step's ``invert(result, source, inverse)`` is checked."""

    transform: Transform[Src, Dst, Options, Inverse]
    options: Options
    source: Src
    target: Dst
    inverse: Inverse
    upstream: Solver | None = None


AnyStep = Step[Any, Any, Any, Any]
"""A step of a chain, whose classes differ from step to step."""


def _applied(
    transform: Transform[Src, Dst, Options, Inverse],
    options: Options,
    spec: SpecBase,
    upstream: Solver | None = None,
    chosen: tuple[AnyBackend, dict[str, Any] | None] | None = None,
) -> Step[Src, Dst, Options, Inverse]:
    """Apply one transform to ``spec`` (solving its upstream stage on ``upstream``, or compiling
    that stage first when ``upstream`` is None and the transform is staged: on the stage's backend,
    else on the ``chosen`` backend (with its options) when that one solves the stage's kind, else
    on the stage kind's default)."""
    if not transform.accepts(spec):
        raise UnsupportedFeature(f"transform {transform.name!r} does not accept problem {spec.name!r}")
    stage = transform.stage(spec, options)
    stage_result = None
    if stage is not None:
        if upstream is None:
            backend, backend_options = stage.backend, None
            if backend is None and chosen is not None and stage.spec.kind in chosen[0].kinds:
                backend, backend_options = chosen[0].name, chosen[1]
            upstream = compile_spec(stage.spec, backend, backend_options)
            stage_result = upstream.solve()
        else:
            stage_result = upstream.solve_spec(stage.spec)
    target, inverse = transform.apply(spec, options, stage_result)
    return Step(transform, options, spec, target, inverse, upstream)


def _from_file(
    transform: AnyTransform,
    options: StrictModel,
    spec: SpecBase,
    source: str,
    field: str = "",
    chosen: tuple[AnyBackend, dict[str, Any] | None] | None = None,
) -> AnyStep:
    """:func:`_applied` on a spec read from ``source``: what the transform cannot build from the file
    (an expression it generates that is undefined or out of range, a spec it generates that is
    invalid) is a SpecError naming the file and ``field`` (``transforms.<i>`` for a requested one)."""
    try:
        return _applied(transform, options, spec, chosen=chosen)
    except ExpressionError as err:
        raise SpecError(f"{transform.name}: {err}", field=field, source=source) from None
    except SpecError as err:
        if err.source != "<spec>":
            raise
        inner = f"{err.field}: " if err.field else ""
        raise SpecError(f"{transform.name}: {inner}{err.reason}", field=field, source=source) from None


def _changed(old: SpecBase, new: SpecBase) -> frozenset[str]:
    """The runtime parameters whose values differ between two specs of the same structure."""
    before, after = old.runtime_parameters(), new.runtime_parameters()
    return frozenset(n for n, v in after.items() if before.get(n) != v)


def _mapped(step: AnyStep, source: SpecBase) -> AnyStep:
    """``step`` for ``source``, its compiled source with other runtime parameter values, by the
    transform's parameter map: the target's values set on the compiled target, new inverse data."""
    values, inverse = step.transform.parameter_map(source, step.inverse)
    target = with_parameter_values(step.target, values)
    return Step(step.transform, step.options, source, target, inverse, step.upstream)


def _settable(path: str, parameters: set[str], fields: dict[str, Any]) -> bool:
    """Whether a dotted ``path`` is a runtime parameter's or lies in an analysis field."""
    return path in parameters or any(path == f or path.startswith(f"{f}.") for f in fields)


def _new_analysis_values(old: SpecBase, new: SpecBase) -> dict[str, Any]:
    """The :meth:`~SpecBase.analysis_values` of ``new`` that differ from ``old``'s."""
    before = old.analysis_values()
    return {path: value for path, value in new.analysis_values().items() if before.get(path) != value}


def _with_analysis_values(step: AnyStep, source: SpecBase, fields: dict[str, Any]) -> AnyStep:
    """``step`` from ``source`` (new analysis values only), its target given those of ``fields``
    it has: no transform reads them, so nothing else changes."""
    kept = {path: value for path, value in fields.items() if path in step.target.analysis_values()}
    return replace(step, source=source, target=with_field_values(step.target, kept))


def _unrequested(spec: SpecBase) -> SpecBase:
    """``spec`` with an empty ``transforms:`` section: what its first transform receives, so that
    the spec the backend gets does not ask for them again."""
    return spec.model_copy(update={"transforms": []}) if spec.transforms else spec


def build_steps(
    spec: SpecBase, backend: AnyBackend, backend_options: dict[str, Any] | None = None
) -> list[AnyStep]:
    """The requested transforms of ``spec`` in order, then the lowering ones to a kind ``backend``
    solves (a staged one's upstream stage on ``backend`` with ``backend_options`` where it solves
    that stage's kind)."""
    chosen = (backend, backend_options)
    steps: list[AnyStep] = []
    current = _unrequested(spec)
    for index, (transform, options) in enumerate(requested_steps(spec)):
        steps.append(_from_file(transform, options, current, spec.source, f"transforms.{index}", chosen))
        current = steps[-1].target
    lowering = lowering_path(current, backend.kinds)
    if lowering is None:
        raise UnsupportedFeature(f"backend {backend.name!r} does not solve kind {spec.kind!r}")
    for transform in lowering:
        steps.append(_from_file(transform, transform.options_model(), current, spec.source, chosen=chosen))
        current = steps[-1].target
    return steps


def check_requested(spec: SpecBase) -> None:
    """What ``gamespec validate`` checks beyond the schema: each requested transform of ``spec``
    applied in order (its options against the problem: a sensitivity weight that names no
    sensitivity, ``S_x1_v`` for ``S_x1_V``, is a SpecError naming the file and ``transforms.<i>``),
    up to the first staged one, whose upstream stage is a solve (validate never solves)."""
    current = _unrequested(spec)
    for index, (transform, options) in enumerate(requested_steps(spec)):
        if transform.stage(current, options) is not None:
            return
        current = _from_file(transform, options, current, spec.source, f"transforms.{index}").target


def transformed(spec: SpecBase, backend: str | None = None) -> SpecBase:
    """The spec the backend receives: ``spec`` after its requested and lowering transforms."""
    steps = build_steps(spec, get_backend(backend_name(spec, backend)))
    return steps[-1].target if steps else spec


def _first_difference(a: Any, b: Any, path: tuple[str, ...] = ()) -> str | None:
    """The dotted path of the first place two JSON-like values differ, None if they are equal."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(a.keys() | b.keys()):
            found = _first_difference(a.get(key), b.get(key), (*path, str(key)))
            if found is not None:
                return found
        return None
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            found = _first_difference(x, y, (*path, str(i)))
            if found is not None:
                return found
        return None
    return None if a == b else ".".join(path) or "<root>"


def status_policy(result: Result) -> Result:
    """The one status policy (DESIGN.md stage 4; README "Statuses and exit codes"): ``optimal``
    only when the solver says so *and* every check with a verdict or a tolerance passes
    (:meth:`Result.failed_checks`); otherwise ``feasible``, the message naming each failed check,
    its value and its tolerance. Applied by the chain to every Result it returns, of every kind."""
    failed = result.failed_checks()
    if result.status is not Status.OPTIMAL or not failed:
        return result
    note = "not optimal: failed check(s) " + "; ".join(str(f) for f in failed)
    message = f"{result.message}; {note}" if result.message else note
    return result.model_copy(update={"status": Status.FEASIBLE, "message": message})


def _better(candidate: Result, best: Result | None, sense: str) -> bool:
    if best is None or best.objective is None:
        return True
    if candidate.objective is None:
        return False
    if sense == "maximize":
        return candidate.objective > best.objective
    return candidate.objective < best.objective


@dataclass
class Solver:
    """A spec compiled for one backend (or, for a study kind, by its study); call :meth:`solve` as
    often as needed (see module doc)."""

    spec: SpecBase
    backend: AnyBackend | Study
    steps: list[AnyStep]
    compiled: CompiledModel
    build_time_s: float
    analyses: Selection = "all"
    """Which analyses every solve of it runs (:mod:`gamespec.analyses`)."""
    _last_mapped: tuple[SpecBase, tuple[bool, tuple[str, ...] | None], list[AnyStep]] | None = field(
        default=None, init=False, repr=False, compare=False
    )

    @property
    def target_spec(self) -> SpecBase:
        """The spec the backend actually solves (after transforms)."""
        return self.steps[-1].target if self.steps else self.spec

    def solve(
        self,
        parameters: dict[str, Any] | None = None,
        guess: Result | None = None,
        inputs: Inputs = None,
    ) -> Result:
        """Solve (again) with new values of the source spec's runtime parameters or dotted fields
        (validated as at load), an optional guess Result of the target spec, and grid ``inputs``
        passed to the compiled model unchanged."""
        if not parameters:
            return self._solve(self.spec, self.steps, guess, inputs)
        return self.solve_spec(with_values(self.spec, parameters), guess, inputs, names=list(parameters))

    def solve_spec(
        self,
        spec: SpecBase,
        guess: Result | None = None,
        inputs: Inputs = None,
        names: list[str] | None = None,
    ) -> Result:
        """Solve ``spec``, the compiled source spec with other runtime parameter values, on the
        compiled model (see :meth:`mapped_steps`); a SpecError (naming ``names``, the parameters
        that were set) when its target differs from the compiled one in more than those values — or
        in its starting point, when neither the caller nor the last transform gives the compiled
        model one."""
        return self._solve(spec, self.mapped_steps(spec, guess is not None, names), guess, inputs)

    def mapped_steps(
        self, spec: SpecBase, guessed: bool = False, names: list[str] | None = None
    ) -> list[AnyStep]:
        """The compiled steps for ``spec`` (cvxpy's ``apply_parameters``): when ``spec`` differs
        from the compiled source in runtime parameter values only, each step's
        :meth:`~gamespec.transforms.base.Transform.parameter_map` gives its target's values and
        inverse data, a step whose source values did not change is kept as compiled, and only a
        step one of whose :meth:`~gamespec.transforms.base.Transform.unmapped` parameters changed,
        or a staged one (its upstream stage is solved again), is re-applied, with every step after
        it. When ``spec`` differs in more (a dotted field that
        is no runtime parameter, a requested transform's option, a starting point), every step is
        re-applied. A re-applied chain must end in the compiled target's structure (``guessed``:
        the caller gives the compiled model a starting point), else a SpecError naming ``names``.
        The steps mapped without re-applying anything are kept for the last ``spec`` (a frozen
        object: a game's best responses re-solve one spec many times with new grid inputs only)."""
        key = (guessed, tuple(names) if names is not None else None)
        if self._last_mapped is not None and self._last_mapped[0] is spec and self._last_mapped[1] == key:
            return self._last_mapped[2]
        current = _unrequested(spec)
        steps: list[AnyStep] = []
        if self._same_structure(spec, names):
            fields = _new_analysis_values(self.spec, spec)
            for old in self.steps:
                changed = _changed(old.source, current)
                if old.upstream is not None or changed & old.transform.unmapped(current):
                    break
                step = _mapped(old, current) if changed else old
                steps.append(_with_analysis_values(step, current, fields) if fields else step)
                current = steps[-1].target
            else:
                self._last_mapped = (spec, key, steps)
                return steps
        requested = [options for _, options in requested_steps(spec)]
        for index in range(len(steps), len(self.steps)):
            old = self.steps[index]
            options = requested[index] if index < len(requested) else old.options
            steps.append(_applied(old.transform, options, current, old.upstream))
            current = steps[-1].target
        last = steps[-1] if steps else None
        started = guessed or (last is not None and last.transform.guess(last.inverse) is not None)
        difference = _first_difference(
            current.structure(with_guess=not started), self._target_structure(with_guess=not started)
        )
        if difference is not None:
            what = ", ".join(names) if names else "the new values"
            raise SpecError(
                f"{what} change(s) the compiled problem beyond its runtime parameters (field "
                f"{difference} of the spec the backend solves); compile it again instead",
                field=", ".join(names or []),
                source=self.spec.source,
            )
        return steps

    def _same_structure(self, spec: SpecBase, names: list[str] | None) -> bool:
        """Whether ``spec`` differs from the compiled source in runtime parameter values only: by
        ``names`` when they are given (each one a runtime parameter), else by its structure."""
        if names is not None:
            paths = {self.spec.parameter_path(n) for n in self.spec.runtime_parameters()}
            fields = self.spec.analysis_values()
            return all(_settable(self.spec.parameter_path(n), paths, fields) for n in names)
        return spec.structure(with_guess=True) == self._source_structure

    @cached_property
    def _source_structure(self) -> dict[str, Any]:
        return self.spec.structure(with_guess=True)

    def _target_structure(self, with_guess: bool) -> dict[str, Any]:
        return self._target_structures[with_guess]

    @cached_property
    def _target_structures(self) -> dict[bool, dict[str, Any]]:
        """The compiled target's structure with and without its starting point, dumped once."""
        return {flag: self.target_spec.structure(with_guess=flag) for flag in (False, True)}

    def _solve(self, spec: SpecBase, steps: list[AnyStep], guess: Result | None, inputs: Inputs) -> Result:
        """Solve the compiled model and map the Result back through ``steps``; its ``solve_time_s``
        is the wall-clock time of all of it (the solve, the checks, the inverse maps, multi-start),
        what the caller waited for, whatever the backend measured inside."""
        started = time.perf_counter()
        target = steps[-1].target if steps else spec
        values = target.runtime_parameters() or None
        last = steps[-1] if steps else None
        start = guess if guess is not None or last is None else last.transform.guess(last.inverse)
        with sourced(self.spec.source):
            result = self.compiled.solve(parameters=values, guess=start, inputs=inputs)
            result = self._kind_analysed(target, result)
            for index in reversed(range(len(steps))):
                step = steps[index]
                result = self._mapped(step, result)
                is_last = index == len(steps) - 1
                if result.ok:
                    result = self._verified(step, result, values, inputs, multistart=is_last)
                elif is_last:
                    result = self._restarted(step, values, inputs) or result
        provenance = Provenance(
            spec_hash=spec_hash(spec),
            source=self.spec.source,
            file_hash=self.spec.file_hash,
            versions=_versions(self.backend),
            created=_dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
            transforms=[step.transform.name for step in steps],
        )
        return status_policy(result).model_copy(
            update={
                "backend": self.backend.name,
                "problem": spec.name,
                "kind": spec.kind,
                "build_time_s": self.build_time_s,
                "solve_time_s": time.perf_counter() - started,
                "parameters": spec.runtime_parameters() or result.parameters,
                "provenance": provenance,
            }
        )

    def _mapped(self, step: AnyStep, result: Result) -> Result:
        """``result`` mapped back through ``step``: its ``invert``, then the selected analyses of the
        transform and of the source's kind."""
        back = step.transform.invert(result, step.source, step.inverse)
        declared = step.transform.analyses()
        back = run_analyses(back, declared, self.analyses, step.source, step.inverse, step.options)
        return self._kind_analysed(step.source, back)

    def _kind_analysed(self, spec: SpecBase, result: Result) -> Result:
        """``result`` with the selected analyses of its kind, not verified when a skipped one
        decides a check."""
        declared = kind_analyses(spec.kind)
        result = run_analyses(result, declared, self.analyses, spec)
        skipped = skipped_checks(declared, self.analyses)
        return _not_verified(result, _skipped(skipped)) if skipped and result.ok else result

    def _unverifiable(self, step: AnyStep) -> str | None:
        """Why ``step.transform.verify`` cannot judge a Result here: the checks it reads that the
        skipped analyses decide (None when every such analysis runs)."""
        skipped = skipped_checks(step.transform.analyses(), self.analyses)
        return _skipped(skipped) if skipped else None

    def _restarted(self, step: AnyStep, values: dict[str, float] | None, inputs: Inputs) -> Result | None:
        """Multi-start: the best verified Result among re-solves of the compiled model from the
        step's restarts (None if none verifies); with the verifying analyses off, the best usable
        one, not verified."""
        best = None
        unverifiable = self._unverifiable(step)
        guesses = step.transform.restarts(step.source, step.inverse)
        for number, start in enumerate(guesses, 1):
            raw = self.compiled.solve(parameters=values, guess=start, inputs=inputs)
            candidate = self._mapped(step, self._kind_analysed(step.target, raw))
            if not candidate.ok:
                continue
            if not unverifiable and step.transform.verify(candidate, step.source, step.inverse) is not None:
                continue
            if _better(candidate, best, step.source.objective_sense):
                verb = "solved" if unverifiable else "verified"
                note = f"{verb} after a re-solve from starting point {number} of {len(guesses)}"
                best = candidate.model_copy(update={"message": f"{candidate.message}; {note}"})
        return best if best is None or not unverifiable else _not_verified(best, unverifiable)

    def _verified(
        self,
        step: AnyStep,
        result: Result,
        values: dict[str, float] | None,
        inputs: Inputs,
        multistart: bool,
    ) -> Result:
        """``result`` if the step verifies it; else the best verified multi-start Result (only the
        last step's restarts start the compiled model), else ``result`` marked not verified; and
        marked not verified, without a multi-start, when the analyses that verify it are off."""
        unverifiable = self._unverifiable(step)
        if unverifiable:
            return _not_verified(result, unverifiable)
        failed = step.transform.verify(result, step.source, step.inverse)
        if failed is None:
            return result
        better = self._restarted(step, values, inputs) if multistart else None
        if better is not None:
            return better
        return _not_verified(result, failed)


def _skipped(checks: list[str]) -> str:
    return f"check(s) {', '.join(checks)} skipped ({SKIPPED})"


def _not_verified(result: Result, why: str) -> Result:
    """``result`` without an optimality claim (``feasible`` for ``optimal``), the message saying why."""
    status = Status.FEASIBLE if result.status is Status.OPTIMAL else result.status
    return result.model_copy(update={"status": status, "message": f"not verified optimal: {why}"})


def compile_spec(
    spec: SpecBase | str | Path,
    backend: str | None = None,
    options: dict[str, Any] | None = None,
    *,
    analyses: Selection | None = None,
) -> Solver:
    """Load (if a path), pick the backend, apply the transforms, and build its model once;
    ``analyses``: which analyses its solves run (None: the file's ``analyses:`` key, else all)."""
    if not isinstance(spec, SpecBase):
        spec = load(spec)
    # the file's choice is "all", "none" or a list of names (checked at load: AnalysesChoice)
    selection = analyses if analyses is not None else cast(Selection, spec.analyses or "all")
    check_names(selection, spec.source)
    study = registry.kind(spec.kind).study if spec.kind in registry.names("gamespec.kinds") else None
    if study is not None:
        return _study(spec, backend or spec.solver.backend or study, options, selection)
    name = backend_name(spec, backend)
    instance = get_backend(name)
    start = time.perf_counter()
    with sourced(spec.source):
        steps = build_steps(spec, instance, options)
        target = steps[-1].target if steps else spec
        compiled = instance.compile(target, instance.options(target, options))
    build = time.perf_counter() - start
    return Solver(spec, instance, steps, compiled, build, selection)


def _study(spec: SpecBase, name: str, options: dict[str, Any] | None, selection: Selection) -> Solver:
    """A study kind compiled by the :class:`~gamespec.compiling.study_protocol.Study` plugin
    ``name`` (the one its kind names, unless the caller or the file names another study), which
    drives the solves of its points itself; no transform applies to a study kind."""
    if name not in registry.names("gamespec.studies"):
        studies = ", ".join(registry.names("gamespec.studies"))
        raise UnsupportedFeature(
            f"kind {spec.kind!r} is a study, run by a study plugin ({studies}), not by backend "
            f"{name!r}; its points' backend is the file's ocp_backend"
        )
    study = registry.load("gamespec.studies", name)()
    start = time.perf_counter()
    compiled = study.compile(spec, study.options(spec, options))
    return Solver(spec, study, [], compiled, time.perf_counter() - start, selection)


def solve(
    spec: SpecBase | str | Path,
    backend: str | None = None,
    *,
    parameters: dict[str, Any] | None = None,
    guess: Result | None = None,
    inputs: Inputs = None,
    options: dict[str, Any] | None = None,
    analyses: Selection | None = None,
) -> Result:
    """Solve a spec (or problem file) once on ``backend`` and return its Result (``analyses`` as
    in :func:`compile_spec`)."""
    solver = compile_spec(spec, backend, options, analyses=analyses)
    return solver.solve(parameters=parameters, guess=guess, inputs=inputs)
