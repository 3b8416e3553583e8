"""The ``flow_field_game`` kind end to end on a uniform flow, where every stage has a closed form:
the discs of the reachable sets, straight nominal paths, an exact linear model (so eq. 5.39 and the
Monte Carlo of the SDE must agree within sampling error), and the bad-input contract."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from gamespec.errors import SpecError
from gamespec.flowfield.problem import evaluate
from gamespec.loader import load, spec_from_dict
from gamespec.solving import solve
from tests.plots.recording import recording

SPEC = {
    "kind": "flow_field_game",
    "name": "uniform",
    "problem": {
        "parameters": {"noise": 0.05},
        "flow": {"drift": [0.4, -0.3], "diffusion": {"identity": "noise"}},
        "pursuer": {"initial": [0, 0], "max_speed": 2, "delta_u": 0.4},
        "evader": {"initial": [1, 0.5], "max_speed": 0.75, "delta_u": 0.15},
        "capture_radius": 0.09,
        "step": 0.2,
        "feedforward": "nominal",
    },
    "method": {
        "grid": {"lower": [-2.5, -3.0], "upper": [4.0, 3.0], "nodes": [53, 49]},
        "levels": [0.4, 0.8],
        "game": {"scheme": "minimax_mixed", "max_iterations": 12},
        "monte_carlo": {"samples": 20000, "seed": 1},
    },
}
T_EXACT = np.hypot(1, 0.5) / (1.6 - 0.6)


@pytest.fixture(scope="module")
def result():
    return solve(spec_from_dict(SPEC))


def test_capture_time_and_point(result) -> None:
    gap = np.array([1.0, 0.5])
    x_f = gap + np.array([0.4, -0.3]) * T_EXACT + 0.6 * T_EXACT * gap / np.linalg.norm(gap)
    dx = 6.5 / 52
    assert result.metrics["capture_time"] == pytest.approx(T_EXACT, abs=0.1 * dx / 1.6)
    assert np.linalg.norm(np.array(result.metrics["capture_point"]) - x_f) < dx
    assert result.checks["capture_time_difference"] < 0.1 * dx / 1.6
    assert max(result.checks["closure_error_pursuer"], result.checks["closure_error_evader"]) < dx
    # the grid-error estimate (the same levels on a grid twice as coarse) is of the true error's size
    estimate = result.metrics["grid_error_estimate"]
    true_error = abs(result.metrics["capture_time"] - T_EXACT)
    assert 0.1 * true_error <= estimate["capture_time"] <= 10 * true_error
    assert result.checks["capture_time_grid_error"] == estimate["capture_time"]
    assert result.metrics["check_tolerances"]["capture_time_grid_error"] == pytest.approx(0.05 * 0.2, rel=0.1)


def test_monte_carlo_agrees_with_eq_5_39(result) -> None:
    """For a uniform flow the linearized model is exact and Euler–Maruyama is exact, so the Monte
    Carlo frequency of capture at T̂ has mean eq. 5.39 (both loops; in closed loop the evader's
    mixed strategy, so the mixture of its support points' probabilities)."""
    carlo = result.metrics["monte_carlo_capture_probability"]
    for loop in ("open_loop", "closed_loop"):
        p = result.metrics[f"capture_probability_{loop}"]
        n = carlo[loop]["samples"]
        assert n >= 20000
        assert abs(carlo[loop]["estimate"] - p) < 4 * np.sqrt(p * (1 - p) / n) + 1e-3


def test_result_reports_the_game_honestly(result) -> None:
    """On a uniform flow the best responses settle (straight paths), and the Result says so by the
    history it reports: the last round changed no player's strategy beyond the tolerance."""
    report = result.metrics["best_response"]
    history = report["history"]
    assert history and result.metrics["game_scheme"] == "minimax_mixed"
    settled = all(change <= report["tolerance"] for change in history[-1]["changes"].values())
    assert result.metrics["game_converged"] is True and report["converged"] is True and settled
    assert result.ok == result.metrics["game_converged"]
    mixture = result.metrics["evader_mixture"]
    assert sum(mixture["weights"]) == pytest.approx(1.0)
    scale = result.metrics["payoff_open_loop"]
    assert result.objective == pytest.approx(scale * np.dot(mixture["weights"], mixture["payoffs"]))
    assert result.checks["max_constraint_violation"] <= 1e-6
    for values in result.metrics["evader_convex_concave"]["payoffs"]:
        assert np.all(np.diff(values) >= -1e-6 * np.abs(values[:-1]))


def test_extremal_backend_agrees(result) -> None:
    other = solve(spec_from_dict(SPEC), backend="extremals", options={"cross_check": False})
    assert other.metrics["capture_time"] == pytest.approx(T_EXACT, abs=1e-3)
    cell_time = 6.5 / 52 / 1.6
    assert other.metrics["capture_time"] == pytest.approx(result.metrics["capture_time"], abs=0.1 * cell_time)


@pytest.mark.parametrize(
    ("path", "value", "field"),
    [
        (("problem", "flow", "drift"), ["x1 +", 0], "problem.flow.drift.0"),
        (("problem", "flow", "drift"), ["y3", 0], "problem.flow.drift.0"),
        (("problem", "pursuer", "max_speed"), 0.5, "problem.pursuer.max_speed"),
        (("problem", "evader", "beta"), 1.5, "problem.evader.beta"),
        (("problem", "nominal_speed_fraction"), 1.2, "problem.nominal_speed_fraction"),
        (("problem", "evader", "initial"), [40, 0], "method.grid"),
        (("method", "grid", "nodes"), [5, 5], "method.grid"),
        (("problem", "payoff"), "max", "problem.payoff"),
    ],
)
def test_bad_input_names_the_field(path: tuple[str, ...], value: object, field: str) -> None:
    data = copy.deepcopy(SPEC)
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(SpecError) as err:
        spec_from_dict(data, source="bad.yaml")
    assert err.value.field.startswith(field)


def test_set_parameter_on_the_command_line(tmp_path: Path, cli) -> None:
    path = tmp_path / "uniform.yaml"
    path.write_text(yaml.safe_dump(SPEC))
    spec = load(path, ["problem.parameters.noise=0.1"])
    assert spec.problem.parameters["noise"] == 0.1
    assert evaluate(spec).field.diffusion(np.zeros((1, 2)))[0, 0, 0] == pytest.approx(0.1)
    code, out, err = cli("validate", path, "--set", "problem.flow.drift=[1]")
    assert code == 2 and "problem.flow.drift" in out + err
    assert cli("validate", path, "--set", "problem.parameters.noise=0.1")[0] == 0


def test_hj_reachability_backend_agrees(result) -> None:
    """The optional JAX engine (same scheme, global Lax–Friedrichs) finds the same capture."""
    pytest.importorskip("hj_reachability")
    other = solve(spec_from_dict(SPEC), backend="hj_reachability", options={"cross_check": False})
    assert other.metrics["reachability"]["engine"].startswith("hj_reachability")
    cell_time = 6.5 / 52 / 1.6
    assert other.metrics["capture_time"] == pytest.approx(result.metrics["capture_time"], abs=0.1 * cell_time)


def test_fig_5_2_from_a_sweep(tmp_path: Path, cli) -> None:
    """``gamespec sweep`` over the noise parameter keeps each point's capture probabilities, and
    ``gamespec plot`` on the folder draws them against it (Fig. 5.2); the stage that does not
    depend on the noise (reachability) is computed once per worker."""
    data = copy.deepcopy(SPEC)
    data["method"]["monte_carlo"]["samples"] = 2000
    data["solver"] = {"backend": "levelset", "options": {"levelset": {"cross_check": False}}}
    path = tmp_path / "uniform.yaml"
    path.write_text(yaml.safe_dump(data))
    code, out, err = cli("sweep", path, "--param", "noise=0.03,0.06", "--out", tmp_path / "study", "--json")
    assert code == 0, err
    rows = json.loads(out)
    assert [r["noise"] for r in rows] == [0.03, 0.06]
    for row in rows:
        assert {"open_loop", "closed_loop"} <= set(row["metrics"]["monte_carlo_capture_probability"])
    with recording() as saved:
        code, out, err = cli("plot", tmp_path / "study", "--out", tmp_path / "figures")
    assert code == 0, err
    (figure,) = [s for s in saved if s.name == "capture_probability_noise.png"]
    drawn = {
        line.get_label(): line
        for line in figure.axes[0].lines
        if f"capture_probability_{line.get_label()}" in rows[0]["metrics"]
    }
    assert "open_loop" in drawn and len(drawn) > 1, list(drawn)
    for loop, line in drawn.items():
        assert list(line.get_xdata()) == [0.03, 0.06]
        assert list(line.get_ydata()) == [r["metrics"][f"capture_probability_{loop}"] for r in rows]


def test_summary_leads_with_the_capture(result) -> None:
    """The summary shows open loop, both closed-loop figures, the saddle gap and the concept."""
    from gamespec.summaries import outcome

    rows = dict(outcome(result))
    m = result.metrics
    assert rows["capture time T̂"] == m["capture_time"]
    assert rows["P(capture at T̂), open loop"] == m["capture_probability_open_loop"]
    lower = "P(capture at T̂), lower value (thesis: the pursuer answers)"
    assert rows[lower] == m["capture_probability_lower_value"]
    assert (
        rows["P(capture at T̂), mixed minimax (worst-case evader)"] == m["capture_probability_minimax_mixed"]
    )
    assert rows["saddle gap v₊ − v₋ (payoff)"].startswith(f"{m['saddle_gap']:.4g}")
    assert rows["solution concept (closed loop)"].startswith(m["solution_concept"])
    assert rows["game converged"] == m["game_converged"]


@pytest.fixture(scope="module")
def lower() -> object:
    data = copy.deepcopy(SPEC)
    data["method"]["game"]["scheme"] = "lower_value"
    data["method"]["monte_carlo"]["samples"] = 0
    return solve(spec_from_dict(data), options={"cross_check": False})


def test_both_solution_concepts_are_reported(result, lower) -> None:
    """Each scheme reports the figure of its concept as the closed loop and the other beside it, the
    same values ``v₋ ≤ v₊`` and saddle gap (:mod:`gamespec.flowfield.concepts`), and no pure saddle
    point in this uniform flow: the gap is far beyond the tolerance."""
    for run, scheme in ((result, "minimax_mixed"), (lower, "lower_value")):
        m = run.metrics
        assert m["solution_concept"] == scheme, run.message
        assert m["capture_probability_closed_loop"] == m[f"capture_probability_{scheme}"]
        assert m["lower_value"] < m["upper_value"]
        assert m["saddle_gap"] == pytest.approx(m["upper_value"] - m["lower_value"])
        assert m["saddle_gap"] > 10 * 1e-3 * m["upper_value"]  # ten times the default method.game.gap
        assert "no pure saddle point" in run.message
        assert m["payoffs"]["pursuer"] == pytest.approx(run.objective) == -m["payoffs"]["evader"]
        assert set(m["check_tolerances"]) == set(m["checks_passed"]) <= set(run.checks)
    assert all(result.metrics["checks_passed"].values()), result.metrics["checks_passed"]
    assert lower.metrics["lower_value"] == pytest.approx(result.metrics["lower_value"], rel=1e-9)
    assert lower.objective == pytest.approx(lower.metrics["lower_value"])
    # here the pursuer's answer to the open-loop evader uses more than ρᵖ − ρᵉ of its spread: no room
    # to copy, so the evader's commitment beats open loop and the lower value is not certified
    ascent = lower.metrics["lower_value_ascent"]
    assert ascent["copy_room"] > 1 and ascent["bound"] is None
    assert ascent["payoffs"][-1] > ascent["payoffs"][0]
    assert lower.checks["lower_value_bracket"] is None
    assert not lower.metrics["checks_passed"]["lower_value_bracket"]
    # the thesis' reading captures more than open loop, a worst-case evader less than the thesis
    m = lower.metrics
    assert m["capture_probability_lower_value"] > m["capture_probability_open_loop"]
    assert m["capture_probability_minimax_mixed"] < m["capture_probability_lower_value"]
