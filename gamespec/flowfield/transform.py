"""``flow_field_game`` → ``flow_covariance_game``, staged (chapter 5): the reachability stage first.

:meth:`FlowGameToCovarianceGame.stage` names the reachability solve (section 5.2; the spec of
:func:`gamespec.flowfield.stages.reachability_spec`), which the solving layer runs on the backend
the caller chose; :meth:`~FlowGameToCovarianceGame.apply` writes the covariance game about its
nominal paths (section 5.3, eqs. 5.5–5.36) and keeps the reachability Result as the inverse data;
:meth:`~FlowGameToCovarianceGame.invert` joins that Result's metrics, arrays and checks to the
game's, in the ``flow_field_game``'s names. The numerics stay in :mod:`gamespec.flowfield`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from gamespec.compiling import NoOptions
from gamespec.flowfield.problem import evaluate
from gamespec.flowfield.spec import FlowCovarianceGameSpec, FlowGameSpec
from gamespec.flowfield.stages import (
    covariance_game_spec,
    flow_game_result,
    reachability_key,
    reachability_spec,
)
from gamespec.result import Result
from gamespec.transforms.base import Stage, Transform


@dataclass(frozen=True)
class Reached:
    """The inverse data: the reachability Result and the values it was computed for
    (:func:`~gamespec.flowfield.stages.reachability_key`)."""

    key: tuple[Any, ...]
    result: Result


class FlowGameToCovarianceGame(Transform[FlowGameSpec, FlowCovarianceGameSpec, NoOptions, Reached]):
    """A flow-field game as its covariance game about the nominal paths of its reachability stage."""

    name: ClassVar[str] = "flow_game_to_covariance_game"
    source_kind: ClassVar[str] = "flow_field_game"
    target_kind: ClassVar[str] = "flow_covariance_game"

    def stage(self, spec: FlowGameSpec, options: NoOptions) -> Stage:
        return Stage(reachability_spec(spec))

    def apply(
        self, spec: FlowGameSpec, options: NoOptions, upstream: Result | None = None
    ) -> tuple[FlowCovarianceGameSpec, Reached]:
        assert upstream is not None, "a staged transform: the solving layer passes the reachability"
        return covariance_game_spec(spec, upstream), Reached(reachability_key(evaluate(spec)), upstream)

    def invert(self, result: Result, spec: FlowGameSpec, inverse_data: Reached) -> Result:
        reach = inverse_data.result
        mapped = flow_game_result(result, reach)
        return mapped.model_copy(update={"kind": spec.kind, "problem": spec.name, "t_final": reach.t_final})
