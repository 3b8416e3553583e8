"""What the backend plugins of the ``lq_stochastic_game`` kind share, so each supplies only its
solver: the options block (a solver's name and its keyword arguments), the compiled model and the
plugin class.

:class:`LQCompiledModel` builds the game for the effective parameter values (the file's, updated by
``parameters``; rebuilt when they change), reports a violated assumption of chapter 4 (eq. 4.27,
section 4.4) as a failed Result, applies Lemma 11 before the mean QP (eq. 4.43), and packs the mean
and covariance games with :func:`~gamespec.lqgame.solution.assemble`. :class:`LQBackend` says
whether the wrapped library imports and which solvers it finds, and refuses a solver it lacks.
"""

from __future__ import annotations

import importlib
from abc import abstractmethod
from collections.abc import Mapping
from typing import Any, ClassVar, TypeVar

from pydantic import Field

from gamespec.compiling import Availability, Backend, CompiledModel, Inputs, refuse_inputs
from gamespec.errors import BackendError, SpecError
from gamespec.lqgame.solution import (
    CovarianceOutcome,
    GameModel,
    MeanOutcome,
    assemble,
    fallback_mean,
    unconstrained_covariance,
)
from gamespec.result import Result, Status
from gamespec.specs.base import StrictModel
from gamespec.specs.lq_game import LQGameSpec


class LQSolverOptions(StrictModel):
    """An LQ backend's options block: the solver's name and its keyword arguments."""

    solver: str = Field(description="The solver's name.")
    solver_options: dict[str, Any] = Field(
        default_factory=dict, description="Keyword arguments passed to the solver."
    )

    def rejected(self, err: Exception) -> BackendError:
        """The solver's complaint about ``solver_options`` as a one-line error."""
        reason = str(err).splitlines()[0] if str(err) else type(err).__name__
        return BackendError(f"{self.solver} rejected solver_options {self.solver_options}: {reason}")


class LQCompiledModel(CompiledModel):
    """The game built for the effective parameter values (the file's, updated by ``parameters``);
    a solve whose values differ from those of the last build rebuilds the game and the backend's
    model, so a solve without ``parameters`` is always the file's problem.

    Hooks: :meth:`_build_solver` (the backend's modelling objects for ``self.model``),
    :meth:`_solve_mean_qp` (the upper game eq. 4.43 of a reachable target) and
    :meth:`_solve_covariance` (by default the UCSG closed form, eq. 4.59).
    """

    def __init__(self, spec: LQGameSpec, options: LQSolverOptions) -> None:
        self.spec = spec
        self.options = options
        self._build(dict(spec.problem.parameters))

    def _build(self, values: dict[str, float]) -> None:
        self.model = GameModel.build(self.spec.game(values))
        self.values = values
        self.failure = self.model.assumption_failure()
        if self.failure is None:
            self._build_solver()

    @abstractmethod
    def _build_solver(self) -> None:
        """Build the backend's modelling objects for ``self.model`` (which meets the assumptions)."""

    @abstractmethod
    def _solve_mean_qp(self, guess: Result | None) -> MeanOutcome:
        """The controller's upper game eq. 4.43 (its target reachable by Lemma 11)."""

    def _solve_covariance(self, guess: Result | None) -> CovarianceOutcome:
        """The covariance game; the UCSG closed form (eq. 4.59) unless a backend does more."""
        return unconstrained_covariance(self.model)

    def solve_mean(self, guess: Result | None = None) -> MeanOutcome:
        """The mean game alone: Lemma 11's verdict, then the backend's QP."""
        unreachable = self.model.unreachable_mean()
        if unreachable:
            return fallback_mean(self.model, Status.INFEASIBLE, unreachable)
        return self._solve_mean_qp(guess)

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        """Rebuild if the effective parameter values changed, then the mean and covariance games."""
        refuse_inputs(inputs, self.spec.kind)
        values = {**self.spec.problem.parameters, **(parameters or {})}
        if values != self.values:
            self._build(values)
        if self.failure:
            result = Result(
                status=Status.ERROR, message=self.failure, metrics=self.model.assumptions.as_metrics()
            )
        else:
            mean, cov = self.solve_mean(guess), self._solve_covariance(guess)
            result = assemble(
                self.model, mean, cov, self.spec.state_names, tolerance=self.spec.method.tolerance
            )
        return result.model_copy(
            update={"parameters": values, "solver_stats": {"solver": self.options.solver}}
        )


LQOptionsT = TypeVar("LQOptionsT", bound=LQSolverOptions)
"""The options model of one LQ backend (a solver name and its keyword arguments, and more)."""


class LQBackend(Backend[LQGameSpec, LQOptionsT]):
    """A backend of the ``lq_stochastic_game`` kind wrapping the solvers of one ``library``.

    Subclasses set ``name``, ``features``, ``options_model``, ``library``, ``model_class`` and
    :meth:`installed_solvers`. Solver names are matched to the installed ones ignoring case.
    """

    kinds: ClassVar[frozenset[str]] = frozenset({"lq_stochastic_game"})
    library: ClassVar[str]
    model_class: ClassVar[type[LQCompiledModel]]

    @classmethod
    @abstractmethod
    def installed_solvers(cls) -> list[str]:
        """The solvers ``library`` finds here (imports it; ImportError when it is missing)."""

    @classmethod
    @abstractmethod
    def probe_options(cls, options: LQOptionsT) -> None:
        """Raise ``options.rejected(...)`` when the solver refuses ``options.solver_options`` (a
        one-variable problem at compile time, so no real solve needs an exception handler)."""

    @classmethod
    def available(cls) -> Availability:
        try:
            solvers = cls.installed_solvers()
        except ImportError as err:
            return Availability(False, f"{cls.library} does not import: {err}")
        if not solvers:
            return Availability(False, f"{cls.library} finds no solver")
        version = importlib.import_module(cls.library).__version__
        return Availability(True, f"{cls.library} {version}; solvers {', '.join(solvers)}")

    @classmethod
    def installed_name(cls, solver: str) -> str:
        """The installed solver ``solver`` names (ignoring case); BackendError when none."""
        solvers = cls.installed_solvers()
        found = [s for s in solvers if s.lower() == solver.lower()]
        if not found:
            raise BackendError(
                f"solver {solver!r} is not installed for {cls.library} (installed: {', '.join(solvers)})"
            )
        return found[0]

    @classmethod
    def validate_options(cls, raw: Mapping[str, Any], source: str = "<spec>") -> LQOptionsT:
        """The options block, its ``solver`` an installed one (checked at load, naming the field)."""
        options = super().validate_options(raw, source)
        try:
            cls.installed_name(options.solver)
        except BackendError as err:
            raise SpecError(str(err), field=f"solver.options.{cls.name}.solver", source=source) from None
        except ImportError:
            pass
        return options

    def _compile(self, spec: LQGameSpec, options: LQOptionsT) -> CompiledModel:
        options = options.model_copy(update={"solver": self.installed_name(options.solver)})
        self.probe_options(options)
        return self.model_class(spec, options)
