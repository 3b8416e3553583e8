"""The CasADi backend's two NLP constructions (flat SX graph, MX graph around the mapped per-point
function) are the same NLP: same optimum, also on a re-solve with new parameter values."""

from __future__ import annotations

import pytest

import gamespec
from gamespec.solving import get_backend
from tests.conftest import PROBLEMS

FILES = [
    PROBLEMS / "ocp" / "cart_pole_swing_up.yaml",
    PROBLEMS / "ch6" / "zermelo_min_time.yaml",
    PROBLEMS / "ch6" / "zermelo_max_range.yaml",
]


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_mx_graph_reaches_the_sx_optimum(path) -> None:
    models = {
        graph: get_backend("casadi").compile(gamespec.load(path, [f"solver.options.casadi.graph={graph}"]))
        for graph in ("sx", "mx")
    }
    first = {graph: model.solve() for graph, model in models.items()}
    assert first["sx"].ok and first["mx"].ok
    assert first["mx"].objective == pytest.approx(first["sx"].objective, rel=1e-8)
    if "rho" in gamespec.load(path).problem.parameters:
        again = {graph: model.solve(parameters={"rho": 8.0}) for graph, model in models.items()}
        assert again["mx"].objective == pytest.approx(again["sx"].objective, rel=1e-8)
