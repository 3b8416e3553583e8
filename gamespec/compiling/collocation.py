"""What the backends that solve ``optimal_control`` specs by direct collocation share: the kinds and
features they declare, the one spelling of NLP options (``solver.options.nlp``), and a compiled
model that says where its grid inputs go and refines its mesh when the file asks. Their numerics
(the backend-neutral :class:`~gamespec.ocp.transcription.Transcription`) live in :mod:`gamespec.ocp`."""

from __future__ import annotations

from abc import abstractmethod
from collections.abc import Mapping
from typing import Any, ClassVar, TypeVar

from gamespec.compiling import Backend, CompiledModel, Inputs
from gamespec.ocp.inputs import InputGrid
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.ocp.transcription import Transcription
from gamespec.result import Result
from gamespec.specs.base import NLP_OPTIONS, SpecBase, StrictModel
from gamespec.specs.ocp import OptimalControlSpec

IPOPT_DEFAULTS: dict[str, Any] = {"mumps_permuting_scaling": 0}
"""IPOPT options every collocation backend passes to IPOPT under the file's own (which override
them). MUMPS's automatic permuting scaling (``ICNTL(6) = 7``, MC64) miscounts the inertia of some
collocation KKT matrices: on COPS particle steering from a flat control guess it reports 601-602
negative eigenvalues for every Hessian shift from 1 to 1e6 where the matrix has exactly m = 600
(a dense Bunch-Kaufman LDL^T and the eigenvalues agree; the reduced Hessian's smallest eigenvalue is
-4), so IPOPT's inertia correction drives the shift to 1e8 and stalls for 3000 iterations. Without
that step MUMPS counts right, IPOPT takes the shift ripopt takes (1) and converges in 17 iterations."""


NlpOptionsT = TypeVar("NlpOptionsT", bound=StrictModel)
"""The options model of one collocation backend (its IPOPT pass-through block is ``nlp_field``)."""


class CollocationBackend(Backend[OptimalControlSpec, NlpOptionsT]):
    """Base of the backends that solve ``optimal_control`` specs by direct collocation of a
    :class:`Transcription` (the same kinds and features for each of them). ``solver.options.nlp``
    holds IPOPT options for all of them: those the backend's options block names (``tol``,
    ``max_iter``, ``max_wall_time``) set that field, the rest go to its pass-through block
    (``nlp_field``); the backend's own block overrides either."""

    nlp_field: ClassVar[str] = ""
    kinds: ClassVar[frozenset[str]] = frozenset({"optimal_control"})
    features: ClassVar[frozenset[str]] = frozenset(
        {
            "ode",
            "free_final_time",
            "path_constraints",
            "boundary_constraints",
            "grid_inputs",
            "design_parameters",
            "integral_constraints",
        }
    )

    def unsupported(self, spec: SpecBase) -> str | None:
        """:meth:`Backend.unsupported`, naming the file's tables where this backend has no
        interpolant for them."""
        reason = super().unsupported(spec)
        if reason is None or not isinstance(spec, OptimalControlSpec) or "tables" in self.features:
            return reason
        tables = ", ".join(spec.problem.tables)
        return reason + (
            f" (table(s) {tables}: no interpolant on {self.name}; casadi has one)" if tables else ""
        )

    def shared_options(self, spec: SpecBase) -> dict[str, Any]:
        nlp = dict(spec.solver.options.get(NLP_OPTIONS, {}))
        own = spec.solver.options.get(self.name, {})
        fields = set(self.options_model.model_fields) - {self.nlp_field}
        named = {k: nlp.pop(k) for k in list(nlp) if k in fields}
        if nlp:
            named[self.nlp_field] = {**nlp, **own.get(self.nlp_field, {})}
        return named


class CollocationModel(CompiledModel):
    """A compiled model of a :class:`Transcription` (``tr``), re-solvable with new grid inputs."""

    tr: Transcription
    options: Any

    @abstractmethod
    def __init__(self, spec: OptimalControlSpec, options: Any, parsed: SymbolicOcp | None = None) -> None:
        """Build the model of ``spec`` with the backend's ``options`` (refinement builds one per
        mesh, passing the first one's ``parsed`` problem: :class:`Transcription`)."""

    def input_grid(self, parameters: Mapping[str, float] | None = None) -> InputGrid:
        """Where ``solve(inputs=...)`` expects its values (see :meth:`Transcription.input_grid`)."""
        return self.tr.input_grid(parameters)

    def solve(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        """One solve on this mesh, then adaptive refinement when ``method.refine`` asks for it
        (:mod:`gamespec.compiling.refinement`)."""
        result = self.solve_once(parameters, guess, inputs)
        if self.tr.spec.method.refine is None:
            return result
        from gamespec.compiling.refinement import refined

        return refined(self, result, parameters, inputs)

    @abstractmethod
    def solve_once(
        self, parameters: dict[str, float] | None = None, guess: Result | None = None, inputs: Inputs = None
    ) -> Result:
        """Solve on this model's mesh."""
