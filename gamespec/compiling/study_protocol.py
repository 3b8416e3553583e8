"""The study contract, beside the backend contract: a study kind (the Table 2.1 study, the §6.4.4
trade-off) is run by a :class:`Study` plugin of the ``gamespec.studies`` entry-point group, not by
a backend.

A backend compiles one spec into one model of its own and solves it; a study drives many solves
(each point's problem on the file's ``ocp_backend``, through the solving chain) into a store and
returns one Result of its kind. The solving layer (:func:`gamespec.solving.compile_spec`) asks the
kind's :class:`~gamespec.registry.Kind` which study runs it and compiles the spec with that study
instead of a backend; ``gamespec solve``, ``--backend NAME`` (the study's name) and the file's
``solver.backend`` / ``solver.options.<name>`` name a study as they name a backend.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar, Protocol, runtime_checkable

from gamespec.compiling import Availability, CompiledModel
from gamespec.specs.base import SpecBase, StrictModel


@runtime_checkable
class Study(Protocol):
    """What the solving layer and ``gamespec backends`` need of a study plugin."""

    name: ClassVar[str]
    kinds: ClassVar[frozenset[str]]
    features: ClassVar[frozenset[str]]
    options_model: ClassVar[type[StrictModel]]

    @classmethod
    def available(cls) -> Availability:
        """Whether the study can run here, with the reason."""

    @classmethod
    def validate_options(cls, raw: Mapping[str, Any], source: str = "<spec>") -> StrictModel:
        """The file's ``solver.options.<name>`` block, validated (a SpecError naming the field)."""

    def options(self, spec: SpecBase, overrides: dict[str, Any] | None = None) -> StrictModel:
        """The study's options for ``spec``: the file's block with the caller's ``overrides``."""

    def compile(self, spec: SpecBase, options: StrictModel) -> CompiledModel:
        """The study ready to run (or resume) as often as :meth:`CompiledModel.solve` is called."""
