"""A local-infeasibility verdict for the Pyomo backend (issue 27, item 6) where the NLP solver gives
none: ripopt has no infeasibility detection (Ipopt's restoration phase that converges to a minimum
of the constraint violation and says ``Infeasible_Problem_Detected``); on a nonlinear infeasible
problem it ends ``Restoration Failed`` or at its iteration limit.

After such an end (:func:`wants_verdict`), or when a first run of :data:`PROBE_ITERATIONS`
iterations left the violation of the constraints where it started (:func:`stagnated`),
:class:`ElasticFeasibility` solves the ℓ1 elastic problem Ipopt's restoration phase solves, from
the point the solver stopped at, in at most the failed run's time again (:data:`ELASTIC_SHARE`):

    min  Σ_i (p_i + n_i)   s.t.   lb_i <= g_i(x) - p_i + n_i <= ub_i,   p, n >= 0,   x in its bounds,

always feasible, so the solver converges on it where it could not on the original. A local minimum
with a slack ``p_i + n_i`` above :data:`VIOLATION` is a point of local infeasibility (the
status ``locally_infeasible``, as IPOPT's on CasADi); a smaller one says a feasible point exists near
there and the original status stands. The defect rows are divided by their state's scale
(:mod:`gamespec.ocp.scaling`), so one absolute threshold serves every row.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from gamespec.result import Status

VIOLATION = 1e-6
"""The largest elastic slack at the elastic problem's minimum that still counts as feasible."""

ELASTIC_SHARE = 1.0
"""The elastic solve may take at most this multiple of the failed run's seconds, or
:data:`ELASTIC_FLOOR_S` when that is more (and never past the solve's wall-clock limit): the
verdict costs at most as much again as a long failure did."""

ELASTIC_FLOOR_S = 10.0
"""Seconds the elastic solve may always take: a failure that ended in a second on an idle machine
must not lose its verdict on a loaded one (the deadline is wall-clock time)."""

PROBE_ITERATIONS = 100
"""ripopt's first run stops after this many iterations (:func:`stagnated`): ripopt has no
infeasibility detection, and on ``x'' = u (1 + 0.1 x^2)``, ``|u| <= 1`` from rest at 1 to rest at 0
in ``t_f = 1`` it ran its 3000 iterations (9.5 s CPU) where IPOPT on CasADi says
``Infeasible_Problem_Detected`` after 24 (0.4 s). The shipped files' runs end within 81 iterations
but orbit raising's (619: its probe stops, the violation has fallen, the full run follows)."""

STAGNATION = 0.1
"""The probe's ℓ1 constraint violation must have fallen below this share of the starting point's
for the solve to go on without an elastic verdict."""


def stagnated(before: float, after: float) -> bool:
    """Whether a probe's :data:`PROBE_ITERATIONS` left the ℓ1 violation of the constraints above
    :data:`VIOLATION` and above :data:`STAGNATION` of the starting point's ``before``: then the
    elastic problem decides from the probe's point; a locally infeasible verdict ends the solve, any
    other goes on with the full run from the same start, so a feasible problem's answer is the one
    a single run gives."""
    return after > VIOLATION and after >= STAGNATION * before


def wants_verdict(status: Status, message: str) -> bool:
    """Whether a solve's end calls for the elastic problem: the iteration limit, or a numerical
    error in ripopt's restoration phase (``Restoration Failed``: where IPOPT's infeasibility
    detection works), not other numerical trouble (the car-vs-train file on pyomo ends ``Numerical
    Difficulties`` after 118 iterations, 115 s CPU; an elastic solve after it raised that to 401 s
    and changed no status)."""
    if status is Status.ITERATION_LIMIT:
        return True
    return status is Status.NUMERICAL_ERROR and "restoration failed" in message.lower()


@dataclass(frozen=True)
class Verdict:
    """The elastic problem's answer: the least ℓ1 violation found and whether it proves local
    infeasibility (a slack above :data:`VIOLATION`)."""

    violation: float
    infeasible: bool

    def message(self) -> str:
        return (
            "locally infeasible: the l1 norm of the constraint violation has a local minimum of"
            f" {self.violation:.3g} near the point the solver stopped at (the elastic problem of the"
            " constraints, solved by the same solver)"
        )


class ElasticFeasibility:
    """The elastic form of a Pyomo model, built on first use; :meth:`verdict` solves it from the
    model's current values and bounds with ``run`` (the backend's way of running its solver on a
    model and loading the solution: True when it ends at a local minimum)."""

    def __init__(self, model: Any) -> None:
        self.model = model
        self._elastic: Any = None
        self._variables: list[tuple[Any, Any]] = []
        self._rows: list[Any] = []

    def _build(self) -> Any:
        import pyomo.environ as pyo

        elastic = self.model.clone()
        self._variables = list(
            zip(
                self.model.component_data_objects(pyo.Var),
                elastic.component_data_objects(pyo.Var),
                strict=True,
            )
        )
        copies = list(elastic.component_data_objects(pyo.Constraint, active=True))
        index = range(len(copies))
        elastic.elastic_p = pyo.Var(index, bounds=(0.0, None), initialize=0.0)
        elastic.elastic_n = pyo.Var(index, bounds=(0.0, None), initialize=0.0)
        elastic.elastic = pyo.ConstraintList()
        for i, con in enumerate(copies):
            elastic.elastic.add(
                (con.lower, con.body - elastic.elastic_p[i] + elastic.elastic_n[i], con.upper)
            )
            con.deactivate()
        for objective in elastic.component_data_objects(pyo.Objective, active=True):
            objective.deactivate()
        elastic.violation = pyo.Objective(
            expr=sum(elastic.elastic_p[i] + elastic.elastic_n[i] for i in index)
        )
        return elastic

    def _slacks(self) -> list[tuple[float, float]]:
        """Per active constraint of the model, at its current values, how far it lies above its
        upper bound and below its lower bound (zero when within; a body that cannot be evaluated
        counts as 0)."""
        import pyomo.environ as pyo

        if not self._rows:
            self._rows = list(self.model.component_data_objects(pyo.Constraint, active=True))
        found = []
        for con in self._rows:
            body = pyo.value(con.body, exception=False)
            body = 0.0 if body is None else float(body)
            below = 0.0 if con.lower is None else max(float(pyo.value(con.lower)) - body, 0.0)
            above = 0.0 if con.upper is None else max(body - float(pyo.value(con.upper)), 0.0)
            found.append((above, below))
        return found

    def violation(self) -> float:
        """The ℓ1 norm of the constraint violation at the model's current values (the elastic
        problem's objective there)."""
        return float(sum(above + below for above, below in self._slacks()))

    def verdict(self, run: Callable[[Any], bool]) -> Verdict | None:
        """The verdict from the model's current values; None when the elastic problem was not
        solved to a local minimum (``run`` returned False)."""
        import pyomo.environ as pyo

        slacks = self._slacks()
        if self._elastic is None:
            self._elastic = self._build()
        elastic = self._elastic
        for source, target in self._variables:
            target.set_value(source.value, skip_validation=True)
            target.setlb(source.lb)
            target.setub(source.ub)
        for i, (above, below) in enumerate(slacks):
            elastic.elastic_p[i].set_value(above)
            elastic.elastic_n[i].set_value(below)
        if not run(elastic):
            return None
        slacks = [pyo.value(elastic.elastic_p[i] + elastic.elastic_n[i]) for i in elastic.elastic_p]
        return Verdict(float(sum(slacks)), max(slacks, default=0.0) > VIOLATION)
