"""Problems shared by the Pyomo tests and the backend benchmarks: the shipped ``optimal_control``
files, and small specs that reach what those files leave out."""

from __future__ import annotations

import copy
from pathlib import Path

import yaml

from gamespec.loader import read_file
from tests.conftest import PROBLEMS

CASADI_ONLY = {"car_vs_train", "f4_min_time_climb", "alpha_pinene"}
"""Files left out of the parity tests: §6.4.3's crossing constraint (a γ = 20 super-Gaussian)
has several local optima and ripopt stops on it with numerical difficulties; the F-4 climb's tables
and alpha-pinene's measurements have no Pyomo form (the backend refuses them, issue 25)."""

OCP_FILES = sorted(
    p
    for p in PROBLEMS.rglob("*.yaml")
    if read_file(p).get("kind") == "optimal_control" and p.stem not in CASADI_ONLY
)
"""Every shipped ``optimal_control`` file (other kinds are skipped), but :data:`CASADI_ONLY`."""

CONSTRAINED = {
    "kind": "optimal_control",
    "name": "double_integrator_speed_limit",
    "problem": {
        "parameters": {"vmax": 1.2, "tf": 1.0},
        "states": {"x": {"initial": 0.0}, "v": {"initial": 0.0, "final": 0.0}},
        "controls": {"a": {"lower": -20, "upper": 20}},
        "dynamics": {"x": "v", "v": "a"},
        "objective": {"lagrange": "a**2 + 0.1*t*v", "mayer": "0.5*(x_f - 1)**2"},
        "time": {"final": "tf"},
        "path_constraints": ["v <= vmax"],
        "boundary_constraints": ["x_f >= 0.9"],
    },
    "method": {"scheme": "radau", "intervals": 15, "degree": 3},
}
"""A minimum-energy double integrator with an active speed limit, an active end constraint, a
time-dependent integrand and a parameter final time: everything the shipped files leave out."""


def atan2_file(folder: Path) -> Path:
    """:data:`CONSTRAINED` with an ``atan2`` in its dynamics (which Pyomo cannot express), as a file."""
    data = copy.deepcopy(CONSTRAINED)
    data["problem"]["dynamics"]["v"] = "(5 + v)*atan2(a, 5 + v)"
    path = folder / "atan2.yaml"
    path.write_text(yaml.safe_dump(data))
    return path
