"""``desensitize``: the requested ``optimal_control`` → ``optimal_control`` rewrite of chapter 6.

:meth:`Desensitize.apply` adds the states of the chosen method (:mod:`gamespec.desensitize.augment`)
and the weighted terms the file asks for — trajectory ``∫‖vec S‖²_Q`` (eq. 6.16; eq. 6.7 for
Seywald's method, ``∫ μᵀQμ`` of eq. 6.62 for C-DOC), final ``‖vec S(t_f)‖²_Q`` (eq. 6.17), fixed
``S(t_f)`` (eq. 6.18) — with every generated expression printed from SymPy. The weights stay
expressions of the file's parameters, so ``--set problem.parameters.alpha=75`` and sweeps re-solve the
compiled model. A ``maximize`` objective subtracts the penalty.

:meth:`Desensitize.invert` (:func:`gamespec.desensitize.penalized.report`, which the ``rcs``
transform shares) keeps the added states in the Result (``S_x1_rho``, ``Phi_*``,
``lambda_*``, ``mu_*``), splits the objective into ``metrics.nominal_objective`` and
``metrics.sensitivity_cost`` (the solver's own quadrature, so they add up to the objective) and
records the state counts. Its analyses (:meth:`Desensitize.analyses`,
:data:`gamespec.desensitize.penalized.ANALYSES`) re-simulate the control under sampled parameters:
``monte_carlo`` (``metrics.monte_carlo``, open loop) and ``lqr_tracking``
(``metrics.monte_carlo.tracking``, eqs. 6.27-6.29), each when the file's ``monte_carlo`` options ask
for it.
"""

from __future__ import annotations

from typing import ClassVar

import sympy as sp

from gamespec.analyses import Analysis
from gamespec.desensitize.augment import METHODS, Augmentation
from gamespec.desensitize.penalized import ANALYSES, FIELD, InverseData, Penalty, augmented_spec, report
from gamespec.desensitize.spec import DesensitizeOptions, Weights
from gamespec.errors import ExpressionError, SpecError
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.result import Result
from gamespec.specs.base import SpecBase
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.symbolic.language import parse, symbol
from gamespec.transforms.base import KeepsParameters, OcpRewrite


class Desensitize(
    KeepsParameters[OptimalControlSpec, InverseData], OcpRewrite[DesensitizeOptions, InverseData]
):
    """Desensitized optimal control (chapter 6) by sensitivity functions, Seywald's method or C-DOC;
    the weights and sensitivities are expressions of the parameters, so every parameter maps to
    itself (:class:`~gamespec.transforms.base.KeepsParameters`)."""

    name: ClassVar[str] = "desensitize"
    plot: ClassVar[str] = "gamespec.desensitize.plotting:plot_desensitized"
    summary: ClassVar[str] = "gamespec.desensitize.report:desensitization_summary"
    options_model = DesensitizeOptions

    def apply(
        self,
        spec: OptimalControlSpec,
        options: DesensitizeOptions | None = None,
        upstream: Result | None = None,
    ) -> tuple[OptimalControlSpec, InverseData]:
        options = options or DesensitizeOptions()
        return desensitize(spec, options)

    def invert(self, result: Result, spec: OptimalControlSpec, inverse_data: InverseData) -> Result:
        return report(result, spec, inverse_data)

    def analyses(self) -> list[Analysis]:
        return list(ANALYSES)


def desensitize(
    spec: OptimalControlSpec, options: DesensitizeOptions
) -> tuple[OptimalControlSpec, InverseData]:
    """The augmented spec and what :func:`report` needs (pure)."""
    uncertain = list(spec.problem.uncertain)
    if not uncertain:
        raise SpecError(
            "desensitization needs uncertain parameters (problem.uncertain)", field=FIELD, source=spec.source
        )
    ocp = SymbolicOcp(spec).parsed()
    aug = METHODS[options.method](ocp, uncertain)
    _check_terms(spec, options, aug)
    params = {n: symbol(n) for n in spec.problem.parameters}
    running = _weighted(options.trajectory, aug.running, params, spec, "trajectory")
    final = _weighted(options.final, aug.final, params, spec, "final")
    penalty = Penalty(running, final)
    measure = Penalty(
        _weighted(_unit(options.trajectory, aug.running), aug.running, params, spec, "trajectory"),
        _weighted(
            _unit(options.final, aug.final) or _unit(options.fixed or None, aug.final),
            aug.final,
            params,
            spec,
            "final",
        ),
    )
    fixed = {key: _parse(raw, params, spec, f"fixed.{key}") for key, raw in options.fixed.items()}
    new = augmented_spec(spec, aug, penalty, fixed)
    counts = len(spec.problem.states), len(new.problem.states)
    inverse = InverseData(aug, penalty, measure, options, *counts, ocp)
    return new, inverse


def _check_terms(spec: OptimalControlSpec, options: DesensitizeOptions, aug: Augmentation) -> None:
    if options.trajectory is None and options.final is None and not options.fixed:
        raise SpecError("ask for at least one of trajectory, final, fixed", field=FIELD, source=spec.source)
    if aug.method == "costate" and (options.final is not None or options.fixed):
        raise SpecError(
            "the costate method (C-DOC) penalizes ∫ μᵀQμ only: use trajectory (μ(t_f) is fixed, eq. 6.63)",
            field=FIELD,
            source=spec.source,
        )
    for key in options.fixed:
        if key not in aug.final:
            raise SpecError(
                f"unknown entry {key!r} (entries: {', '.join(aug.final)})",
                field=f"{FIELD}.fixed.{key}",
                source=spec.source,
            )


def _parse(raw: float | str, params: dict[str, sp.Symbol], spec: SpecBase, where: str) -> sp.Expr:
    try:
        return sp.sympify(parse(raw, params))
    except ExpressionError as err:
        raise SpecError(str(err), field=f"{FIELD}.{where}", source=spec.source) from None


def _unit(weights: Weights | None, entries: dict[str, sp.Expr]) -> Weights | None:
    """Weight 1 on the entries ``weights`` names (all of them for a single weight)."""
    if weights is None:
        return None
    return dict.fromkeys(weights if isinstance(weights, dict) else entries, 1.0)


def _weighted(
    weights: Weights | None,
    entries: dict[str, sp.Expr],
    params: dict[str, sp.Symbol],
    spec: SpecBase,
    term: str,
) -> sp.Expr:
    """``Σ w_e · e²`` over the entries (eq. 6.16/6.17 with a diagonal Q)."""
    if weights is None:
        return sp.Integer(0)
    if not isinstance(weights, dict):
        weights = dict.fromkeys(entries, weights)
    total = sp.Integer(0)
    for key, raw in weights.items():
        if key not in entries:
            raise SpecError(
                f"unknown entry {key!r} (entries: {', '.join(entries)})",
                field=f"{FIELD}.{term}.{key}",
                source=spec.source,
            )
        total += _parse(raw, params, spec, f"{term}.{key}") * entries[key] ** 2
    return total
