"""What the backends that solve ``optimal_control`` specs by direct collocation share: the kinds and
features they declare, and a compiled model that says where its grid inputs go. Their numerics (the
backend-neutral :class:`~gamespec.ocp.transcription.Transcription`) live in :mod:`gamespec.ocp`."""

from __future__ import annotations

from collections.abc import Mapping
from typing import ClassVar

from gamespec.backend import Backend, CompiledModel
from gamespec.ocp.inputs import InputGrid
from gamespec.ocp.transcription import Transcription


class CollocationBackend(Backend):
    """Base of the backends that solve ``optimal_control`` specs by direct collocation of a
    :class:`Transcription` (the same kinds and features for each of them)."""

    kinds: ClassVar[frozenset[str]] = frozenset({"optimal_control"})
    features: ClassVar[frozenset[str]] = frozenset(
        {"ode", "free_final_time", "path_constraints", "boundary_constraints", "grid_inputs"}
    )


class CollocationModel(CompiledModel):
    """A compiled model of a :class:`Transcription` (``tr``), re-solvable with new grid inputs."""

    tr: Transcription

    def input_grid(self, parameters: Mapping[str, float] | None = None) -> InputGrid:
        """Where ``solve(inputs=...)`` expects its values (see :meth:`Transcription.input_grid`)."""
        return self.tr.input_grid(parameters)
