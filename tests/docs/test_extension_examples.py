"""The "Extending gamespec" examples (docs/examples/) run: a new kind, backend, transform, plotter
and command, each registered in-process as an installed plugin's entry point would be."""

from __future__ import annotations

import math
import runpy

import matplotlib.pyplot as plt
import pytest

import gamespec
from gamespec import registry
from tests.conftest import ROOT

EXAMPLES = ROOT / "docs" / "examples"
PARTS = ("kind", "backend", "transform", "plotter", "command")


@pytest.fixture
def projectile():
    """Register the example plugins for one test, then remove them again."""
    saved = {group: dict(objects) for group, objects in registry._IN_PROCESS.items()}
    for part in PARTS:
        runpy.run_path(str(EXAMPLES / f"projectile_{part}.py"))
    yield gamespec.load(EXAMPLES / "projectile.yaml")
    registry._IN_PROCESS.clear()
    registry._IN_PROCESS.update(saved)
    registry.load.cache_clear()


def _closed_form_range(spec) -> float:
    return spec.speed**2 * math.sin(2 * math.radians(spec.angle)) / spec.gravity


def test_new_kind_and_backend(projectile) -> None:
    assert projectile.kind == "projectile" and projectile.solver.options["ballistic"] == {"samples": 51}
    result = gamespec.solve(projectile)
    assert result.backend == "ballistic" and result.status is gamespec.Status.OPTIMAL
    assert len(result.time) == 51
    assert result.metrics["range"] == pytest.approx(_closed_form_range(projectile), rel=1e-12)


def test_bad_backend_option_names_the_field(projectile) -> None:
    with pytest.raises(gamespec.SpecError, match=r"solver\.options\.ballistic\.samples"):
        gamespec.solve(gamespec.load(EXAMPLES / "projectile.yaml", ["solver.options.ballistic.samples=1"]))


def test_new_transform_lowers_to_an_ocp_that_casadi_integrates(projectile) -> None:
    """Collocation of the lowered OCP (an independent integration) lands where the closed form does."""
    result = gamespec.solve(projectile, "casadi")
    assert result.kind == "projectile" and result.status is gamespec.Status.OPTIMAL
    assert result.metrics["range"] == pytest.approx(_closed_form_range(projectile), rel=1e-8)
    assert abs(result.states["y"][-1]) < 1e-8


def test_new_plotter(projectile, tmp_path) -> None:
    from gamespec.plotting import plot_result

    opened = []
    real = plt.subplots
    plt.subplots = lambda *a, **k: opened.append(real(*a, **k)) or opened[-1]
    try:
        paths = plot_result(gamespec.solve(projectile), tmp_path)
    finally:
        plt.subplots = real
    assert [p.name for p in paths] == ["flight.png"] and paths[0].stat().st_size > 0
    (ax,) = opened[0][0].axes
    assert ax.get_xlabel() == "x [m]" and "ballistic, optimal" in ax.get_title()
    assert ax.get_legend().get_texts()[0].get_text() == "flight"


def test_new_command(projectile, cli) -> None:
    code, out, err = cli("projectile", "range", "20", "30")
    assert code == 0, err
    assert f"range {_closed_form_range(projectile):.6g}" in out
