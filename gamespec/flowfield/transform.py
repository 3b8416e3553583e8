"""``flow_field_game`` → ``flow_covariance_game``, staged (chapter 5): the reachability stage first.

:meth:`FlowGameToCovarianceGame.stage` names the reachability solve (section 5.2; the spec of
:func:`gamespec.flowfield.stages.reachability_spec`), which the solving layer runs on the backend
the caller chose; :meth:`~FlowGameToCovarianceGame.apply` writes the covariance game about its
nominal paths (section 5.3, eqs. 5.5–5.36) and keeps the reachability Result as the inverse data;
:meth:`~FlowGameToCovarianceGame.invert` joins that Result's metrics, arrays and checks to the
game's, in the ``flow_field_game``'s names. The numerics stay in :mod:`gamespec.flowfield`.
"""

from __future__ import annotations

from typing import ClassVar

from gamespec.compiling import NoOptions
from gamespec.flowfield.spec import FlowCovarianceGameSpec, FlowGameSpec
from gamespec.flowfield.stages import covariance_game_spec, flow_game_result, reachability_spec
from gamespec.result import Result
from gamespec.transforms.base import Stage, Transform


class FlowGameToCovarianceGame(Transform[FlowGameSpec, FlowCovarianceGameSpec, NoOptions, Result]):
    """A flow-field game as its covariance game about the nominal paths of its reachability stage."""

    name: ClassVar[str] = "flow_game_to_covariance_game"
    source_kind: ClassVar[str] = "flow_field_game"
    target_kind: ClassVar[str] = "flow_covariance_game"

    def stage(self, spec: FlowGameSpec, options: NoOptions) -> Stage:
        return Stage(reachability_spec(spec))

    def apply(
        self, spec: FlowGameSpec, options: NoOptions, upstream: Result | None = None
    ) -> tuple[FlowCovarianceGameSpec, Result]:
        assert upstream is not None, "a staged transform: the solving layer passes the reachability"
        return covariance_game_spec(spec, upstream), upstream

    def invert(self, result: Result, spec: FlowGameSpec, inverse_data: Result) -> Result:
        reach = inverse_data
        mapped = flow_game_result(result, reach)
        return mapped.model_copy(update={"kind": spec.kind, "problem": spec.name, "t_final": reach.t_final})
