"""The ``levelset``, ``extremals`` and ``hj_reachability`` backends of chapter 5's two stages.

Each solves the reachability stage, kind ``flow_reachability`` (:mod:`.reachability`: level sets
of eq. 5.22 in NumPy or JAX, or extremal shooting, then the nominal paths), and the covariance game
about its nominal paths, kind ``flow_covariance_game`` (:mod:`.game`, the same for all three). A
``flow_field_game`` reaches them through the staged transform :mod:`gamespec.flowfield.transform`:
the solving layer solves its reachability stage on the backend the caller chose, and that backend
then solves the game, so ``--backend extremals`` picks the reachability method as before.
"""

from __future__ import annotations

from typing import ClassVar

from gamespec.compiling import Availability, Backend, CompiledModel
from gamespec.flowfield.spec import FlowCovarianceGameSpec, FlowReachabilitySpec
from gamespec_levelset.game import CovarianceGameModel
from gamespec_levelset.options import FlowGameOptions
from gamespec_levelset.reachability import ReachabilityModel

FlowStageSpec = FlowReachabilitySpec | FlowCovarianceGameSpec
"""The two stage kinds of chapter 5's chain this backend solves (reachability, then the game)."""


class _FlowGameBackend(Backend[FlowStageSpec, FlowGameOptions]):
    kinds: ClassVar[frozenset[str]] = frozenset({"flow_reachability", "flow_covariance_game"})
    options_model = FlowGameOptions
    method: ClassVar[str]

    def _compile(self, spec: FlowStageSpec, options: FlowGameOptions) -> CompiledModel:
        if isinstance(spec, FlowReachabilitySpec):
            return ReachabilityModel(spec, self.method, options)
        return CovarianceGameModel(spec, options)


class LevelSetBackend(_FlowGameBackend):
    """Reachability by the level-set equation 5.22 on the file's grid, in NumPy: each step updates
    only the box around the levels the capture search reads (:mod:`gamespec.flowfield.band`).
    Nothing to compile, so the fastest for one solve; see ``hj_reachability`` for repeated solves on
    one grid in one process."""

    name = "levelset"
    method = "levelset"


class ExtremalBackend(_FlowGameBackend):
    """Reachability by extremal shooting (no grid)."""

    name = "extremals"
    method = "extremals"


class HJReachabilityBackend(_FlowGameBackend):
    """Reachability by hj_reachability (JAX) on the file's grid (WENO5, TVD-RK3; the scheme of
    ``method.scheme`` is not used), single precision, the whole grid each step, one XLA program for
    both agents' step compiled on the first solve for a grid, field and speeds (seconds) and reused
    by later solves in the process. The fast option for many solves on one grid in one process
    (per step about twice as fast as NumPy on the whole grid); for one solve, ``levelset`` is
    faster. Optional: needs ``pip install hj-reachability jax``."""

    name = "hj_reachability"
    method = "hj_reachability"

    @classmethod
    def available(cls) -> Availability:
        try:
            import hj_reachability
            import jax
        except ImportError as err:
            return Availability(False, f"optional; pip install hj-reachability jax ({err})")
        return Availability(
            True, f"hj_reachability {hj_reachability.__version__}, jax {jax.__version__} (CPU)"
        )
