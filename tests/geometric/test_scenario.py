"""The ``pursuit_scenario`` kind end to end: Theorems 3–4, §3.3.1, problem files, CLI, plots."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from gamespec_geometric.plot import plot_scenario
from gamespec_geometric.simulation import simulate
from hypothesis import given, settings
from hypothesis import strategies as st

import gamespec
from gamespec.errors import SpecError
from gamespec.loader import spec_from_dict
from tests.conftest import PROBLEMS

SEEDS = st.integers(0, 2**32 - 1)
CH3 = sorted(p for p in (PROBLEMS / "ch3").glob("*.yaml") if gamespec.load(p).kind == "pursuit_scenario")
EVADER_STRATEGIES = [
    {"type": "pure_evasion"},
    {"type": "blind", "headings": ["-pi/4", "pi/2", "3*pi/4"], "switch_period": 0.7},
    {"type": "fixed", "heading": 1.0},
]


def _scenario(seed: int, n: int, m: int, heterogeneous: bool, strategy: str = "cb") -> dict:
    rng = np.random.default_rng(seed)
    evader_strategies = [
        dict(EVADER_STRATEGIES[k], **({"seed": seed} if k == 1 else {})) for k in rng.integers(0, 3, m)
    ]
    return {
        "kind": "pursuit_scenario",
        "pursuers": {
            "positions": rng.uniform(-8, 8, (n, 2)).tolist(),
            "speed": rng.uniform(1.0, 1.5, n).tolist() if heterogeneous else 1.0,
            "strategy": strategy,
        },
        "evaders": {
            "positions": rng.uniform(-8, 8, (m, 2)).tolist(),
            "speed": rng.uniform(0.3, 0.7, m).tolist() if heterogeneous else 0.6,
            "strategy": evader_strategies,
        },
        "capture_radius": 0.1,
        "time_step": 0.05,
        "horizon": 1.0,
    }


def capture_time_bound(data: dict) -> float:
    """A horizon by which Theorems 3–4 guarantee every capture (Lemmas 6 and 8, phase by phase).

    In each phase the current shortest time (Definition 6) falls at rate at least
    ``kappa = min (u_i - v_j) / (u_i + v_j)``; it starts below ``D / (u_min + v_min)``, where the
    distance between any two players is at most ``D = D0 + 2 u_max t``.
    """
    players = np.array(data["pursuers"]["positions"] + data["evaders"]["positions"])
    u = np.atleast_1d(data["pursuers"]["speed"])
    v = np.atleast_1d(data["evaders"]["speed"])
    kappa = np.min((u[:, None] - v[None, :]) / (u[:, None] + v[None, :]))
    diameter = np.max(np.linalg.norm(players[:, None] - players[None], axis=2))
    t = 0.0
    for _ in data["evaders"]["positions"]:
        t += (diameter + 2 * u.max() * t) / (u.min() + v.min()) / kappa
    return t


@settings(max_examples=15, deadline=None)
@given(SEEDS, st.integers(1, 6), st.integers(1, 3), st.booleans())
def test_theorems_3_and_4_every_evader_is_captured(seed: int, n: int, m: int, heterogeneous: bool) -> None:
    """AVAA (homogeneous) and A2 (heterogeneous) capture every evader before the bound of Lemmas 6/8,
    the shortest time never grows between captures and its pair is always allocated (Lemmas 5/7)."""
    data = _scenario(seed, n, m, heterogeneous)
    data["horizon"] = capture_time_bound(data) + 1.0
    result = gamespec.solve(spec_from_dict(data))
    assert result.status == gamespec.Status.SIMULATED, result.message
    assert all(t is not None for t in result.metrics["capture_times"])
    homogeneous = (
        np.ptp(result.metrics["pursuer_speeds"]) == 0 and np.ptp(result.metrics["evader_speeds"]) == 0
    )
    assert result.metrics["algorithm"] == ("avaa" if homogeneous else "a2")
    assert result.checks["shortest_pair_unassigned_steps"] == 0
    increase = result.checks["shortest_time_max_increase"]
    assert increase is None or increase <= 1e-12


@settings(max_examples=15, deadline=None)
@given(SEEDS, st.integers(2, 7), st.booleans(), st.sampled_from(["cb", "pp"]))
def test_redundant_pursuer_stays_redundant(seed: int, n: int, heterogeneous: bool, strategy: str) -> None:
    """§3.3.1: once a pursuer is redundant against the single evader, it stays redundant until capture."""
    data = _scenario(seed, n, 1, heterogeneous, strategy)
    data["horizon"] = capture_time_bound(data) + 1.0
    run = simulate(spec_from_dict(data))
    redundant = run.allocation[:-1] < 0
    became = np.cumsum(redundant, axis=0) > 0
    assert np.array_equal(redundant, became)


@pytest.mark.parametrize("path", CH3, ids=lambda p: p.stem)
def test_problem_file_solves_and_captures_everyone(path: Path) -> None:
    result = gamespec.solve(path)
    assert result.status == gamespec.Status.SIMULATED, result.message
    capture_times = result.metrics["capture_times"]
    assert all(t is not None for t in capture_times)
    assert result.t_final == pytest.approx(max(capture_times))
    pursuers, evaders = result.states["pursuers"], result.states["evaders"]
    for j, (t, i) in enumerate(zip(capture_times, result.metrics["capturers"], strict=True)):
        k = np.searchsorted(result.time, t)
        gap = np.linalg.norm(pursuers[k - 1 : k + 1, i] - evaders[k - 1 : k + 1, j], axis=1).min()
        assert gap <= 2 * result.metrics["capture_radius"] + 2 * result.time[1]
    stopped = np.all(result.states["pursuers"][1:] == result.states["pursuers"][:-1], axis=2)
    assert np.array_equal(stopped, result.arrays["allocation"][:-1] < 0)


def test_solve_json_save_load_and_plot(cli, tmp_path: Path) -> None:
    path = PROBLEMS / "ch3" / "mpse_five_on_one_cb.yaml"
    code, out, _ = cli("solve", path, "--json", "--out", tmp_path / "run")
    assert code == 0
    data = json.loads(out)
    assert data["status"] == "simulated" and data["backend"] == "geometric"
    assert len(data["metrics"]["capture_times"]) == 1 and data["metrics"]["allocation_history"]
    loaded = gamespec.Result.load(tmp_path / "run")
    assert np.array_equal(loaded.arrays["allocation"], gamespec.solve(path).arrays["allocation"])
    code, out, _ = cli("plot", tmp_path / "run")
    assert code == 0
    assert (tmp_path / "run" / "snapshots.png").stat().st_size > 0


def test_animation_writes_a_gif(tmp_path: Path, monkeypatch) -> None:
    """A GIF of few frames at a low resolution (what an animation shows: tests/plots)."""
    import gamespec_geometric.plot as scenario_plots
    import matplotlib

    monkeypatch.setattr(scenario_plots, "_FRAMES", 8)
    monkeypatch.setitem(matplotlib.rcParams, "savefig.dpi", 20)
    data = _scenario(3, 3, 1, heterogeneous=False)
    data["horizon"] = capture_time_bound(data) + 1.0
    result = gamespec.solve(spec_from_dict(data))
    written = plot_scenario(result, tmp_path, animate=True)
    assert (tmp_path / "scenario.gif") in written
    assert (tmp_path / "scenario.gif").read_bytes()[:3] == b"GIF"


def test_parameters_override_the_capture_radius() -> None:
    solver = gamespec.compile_spec(PROBLEMS / "ch3" / "mpse_five_on_one_cb.yaml")
    small, large = solver.solve({"capture_radius": 0.05}), solver.solve({"capture_radius": 0.5})
    assert large.t_final < small.t_final
    with pytest.raises(SpecError, match="unknown parameter"):
        solver.solve({"speed": 2.0})


def _write(tmp_path: Path, changes: dict) -> Path:
    data = yaml.safe_load((PROBLEMS / "ch3" / "mpme_ten_on_five.yaml").read_text())
    for dotted, value in changes.items():
        *parents, key = dotted.split(".")
        node = data
        for part in parents:
            node = node[part]
        node[key] = value
    path = tmp_path / "bad.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.mark.parametrize(
    ("changes", "needles"),
    [
        (
            {"evaders.positions": [[0.0, 3.0], [-8.0, -7.0]]},
            ["pursuer 0 and evader 1 coincide", "evaders.positions"],
        ),
        (
            {"pursuers.positions": [[1.0, 1.0], [1.0, 1.0]]},
            ["pursuer 0 and pursuer 1 coincide at (1.0, 1.0)"],
        ),
        ({"pursuers.speed": -1.0}, ["pursuers.speed: pursuer speed must be a positive number"]),
        ({"pursuers.speed": [1.0] * 9 + [0.0]}, ["pursuers.speed: ", "got [1.0"]),
        ({"evaders.speed": -0.5}, ["evaders.speed: evader speed must be a positive number"]),
        ({"evaders.speed": 1.0}, ["eq. 3.29", "pursuers.speed"]),
        ({"pursuers.speed": [1.0, 0.5]}, ["2 speeds for 10 positions", "pursuers.speed"]),
        ({"pursuers.positions": []}, ["pursuer team is empty", "pursuers.positions"]),
        ({"evaders.positions": []}, ["evader team is empty", "evaders.positions"]),
        ({"evaders.strategy": {"type": "fixed", "heading": "pi/x"}}, ["evaders.strategy", "heading"]),
        ({"time_step": 0.0}, ["time_step"]),
    ],
)
def test_bad_scenario_exits_2_with_the_reason(cli, tmp_path: Path, changes: dict, needles: list[str]) -> None:
    code, _, err = cli("solve", _write(tmp_path, changes))
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert "np.float64" not in lines[0] and "constrained-float" not in lines[0]
    for needle in needles:
        assert needle in lines[0], (needle, lines[0])
