"""Shared by the desensitization tests: the chapter 6 files, solving them, re-simulating a Result."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import yaml

from gamespec.desensitize.simulate import Trajectories, rk4
from gamespec.loader import spec_from_dict
from gamespec.ocp.control_signal import transcribed_signal
from gamespec.ocp.symbolic import SymbolicOcp
from gamespec.result import Result
from gamespec.solving import compile_spec
from gamespec.specs.ocp import OptimalControlSpec
from gamespec.symbolic.language import symbol
from tests.conftest import PROBLEMS

CH6 = PROBLEMS / "ch6"
TRAJECTORY = CH6 / "zermelo_trajectory_desensitized.yaml"
FINAL = CH6 / "zermelo_final_state_desensitized.yaml"
FIXED = CH6 / "zermelo_fixed_final_sensitivity.yaml"
SEYWALD = CH6 / "zermelo_seywald.yaml"
LQR_FILES = [CH6 / f"cdoc_lqr_{c}.yaml" for c in ("b_uncertain", "a_uncertain", "marginal")]
NEW_FILES = [TRAJECTORY, FINAL, FIXED, SEYWALD, *LQR_FILES]


class FileSolver:
    """A desensitized problem (``data`` without its ``transforms`` section, plus the ``desensitize``
    request) compiled once through the solving chain on one backend, re-solved for new parameters."""

    def __init__(self, data: Mapping, request: Mapping, backend: str = "casadi") -> None:
        self.request = dict(request)
        full = {**data, "transforms": [{"desensitize": self.request}]}
        self.solver = compile_spec(spec_from_dict(full), backend)
        self.spec = OptimalControlSpec.model_validate({**data, "transforms": []})
        self.target = self.solver.target_spec

    def solve(self, parameters: Mapping[str, float] | None = None) -> Result:
        return self.solver.solve(parameters=dict(parameters or {}))


def file_solver(
    path: Path,
    backend: str = "casadi",
    edit: Mapping | None = None,
    uncertain: Mapping | None = None,
    method: Mapping | None = None,
) -> FileSolver:
    """The file's problem with its request changed by ``edit``, its uncertain section by
    ``uncertain`` and its method section by ``method``."""
    data = yaml.safe_load(Path(path).read_text())
    request = data.pop("transforms")[0]["desensitize"] | dict(edit or {})
    data["problem"]["uncertain"] |= dict(uncertain or {})
    data["method"] |= dict(method or {})
    return FileSolver(data, request, backend)


def resimulate(
    spec: OptimalControlSpec,
    result: Result,
    params: Mapping[str, np.ndarray | float],
    steps: int = 2000,
    t0: float | None = None,
    x0: np.ndarray | None = None,
) -> Trajectories:
    """The file's dynamics under the Result's control from ``t0`` (default: the start) and ``x0``
    (default: the Result's state there), for each value of the parameter arrays."""
    ocp = SymbolicOcp(spec)
    values = {symbol(k): v for k, v in {**result.parameters, **params}.items()}
    samples = max([np.size(v) for v in params.values()] + [1] + ([x0.shape[1]] if x0 is not None else []))
    start = float(result.time[0]) if t0 is None else t0
    if x0 is None:
        x0 = np.array([[np.interp(start, result.time, result.states[s])] * samples for s in ocp.states])
    u = transcribed_signal(result, ocp.controls)
    return rk4(ocp, x0, u, values, start, float(result.t_final), steps)
