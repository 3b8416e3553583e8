"""Small points of the command line: help text, --version, a clean --out, show --transformed of a
continuous LQ game."""

from __future__ import annotations

import math
from importlib.metadata import version

import pytest
import yaml

import gamespec
from tests.conftest import PROBLEMS


def test_sweep_help_shows_the_range_syntax(cli) -> None:
    code, out, _ = cli("sweep", "--help")
    assert code == 0 and "name=a:b:n" in out


def test_version(cli) -> None:
    code, out, _ = cli("--version")
    assert code == 0 and out.strip() == f"gamespec {version('gamespec')}"


def test_resolving_into_an_existing_out_removes_the_old_figures(cli, tmp_path) -> None:
    out = tmp_path / "run"
    code, _, err = cli("solve", PROBLEMS / "ch6/zermelo_min_time.yaml", "--out", out, "--plot")
    assert code == 0, err
    stale = out / "old_animation.gif"
    stale.write_bytes(b"GIF89a")
    code, _, err = cli("solve", PROBLEMS / "ch2/one_on_one_pure_evasion.yaml", "--out", out)
    assert code == 0, err
    assert not list(out.glob("*.png")) and not stale.exists()
    assert gamespec.Result.load(out).problem == "one_on_one_pure_evasion"


def test_a_folder_without_a_result_keeps_its_images(cli, tmp_path) -> None:
    keep = tmp_path / "mine.png"
    keep.write_bytes(b"png")
    code, _, err = cli("solve", PROBLEMS / "ch2/one_on_one_pure_evasion.yaml", "--out", tmp_path)
    assert code == 0, err
    assert keep.exists()


def test_show_transformed_of_a_continuous_lq_game_gives_the_zero_order_hold(cli, tmp_path) -> None:
    """The missile model (eq. 4.68): ẏ = ẏ, ÿ = a_e − a_p, ȧ_e = (v − a_e)/τ_e, ȧ_p = (u − a_p)/τ_p;
    its exact discretization over dt has A[0][1] = dt, A[2][2] = exp(−dt/τ_e), A[3][3] =
    exp(−dt/τ_p) and B[3] = 1 − exp(−dt/τ_p) (eq. 4.70)."""
    code, out, err = cli("show", PROBLEMS / "ch4/missile_endgame.yaml", "--transformed")
    assert code == 0, err
    data = yaml.safe_load(out)
    problem = data["problem"]
    assert problem["continuous"] is None and "zero-order hold" in data["description"]
    A, B = problem["discrete"]["A"], problem["discrete"]["B"]
    dt, tau_e, tau_p = (problem["parameters"][k] for k in ("dt", "tau_e", "tau_p"))
    assert A[0][1] == pytest.approx(dt, rel=1e-12)
    assert A[2][2] == pytest.approx(math.exp(-dt / tau_e), rel=1e-12)
    assert A[3][3] == pytest.approx(math.exp(-dt / tau_p), rel=1e-12)
    assert B[3][0] == pytest.approx(1 - math.exp(-dt / tau_p), rel=1e-12)
    again = gamespec.spec_from_dict(data)
    assert again.kind == "lq_stochastic_game" and again.problem.discrete is not None


def test_the_compare_gap_of_a_saddle_point_game_is_to_the_median() -> None:
    """A minimization's reference is its lowest trusted objective; a saddle value has no better
    side, so the rows are measured against their median (two rows: equal gaps either side)."""
    from gamespec.studies.compare import compare_backends, reference_objective

    assert reference_objective([3.0, 1.0, 2.0], "minimize") == 1.0
    assert reference_objective([3.0, 1.0, 2.0], "maximize") == 3.0
    assert reference_objective([3.0, 1.0, 2.0], "saddle") == 2.0
    spec = gamespec.load(PROBLEMS / "ch4/test_example_mean_steering.yaml", ["method.monte_carlo.samples=0"])
    assert spec.objective_sense == "saddle"
    rows = compare_backends(spec, [("qp", "proxqp"), ("cvxpy", "clarabel")])
    gaps = [r["relative_gap"] for r in rows]
    assert all(r["status"] == "optimal" for r in rows)
    assert gaps[0] == pytest.approx(gaps[1], rel=1e-9, abs=1e-15)
