"""Statuses mean one thing in every kind, and exit codes follow from them (README, "Statuses")."""

from __future__ import annotations

import json

import pytest
import yaml

import gamespec
from gamespec.result import OK_STATUSES, Status, status_ok
from tests.conftest import ROOT


def _status_table(text: str) -> dict[str, str]:
    """The rows of the status table (the one headed ``| status |``): status → the rest of its row."""
    table = text[text.index("| status |") :].split("\n\n")[0]
    rows = {}
    for line in table.splitlines()[2:]:
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        rows[cells[0].strip("`")] = " | ".join(cells[1:])
    return rows


@pytest.mark.parametrize("document", ["README.md", "docs/statuses.md"])
def test_every_status_is_in_the_table_with_its_exit_code(document: str) -> None:
    rows = _status_table((ROOT / document).read_text())
    assert set(rows) == {s.value for s in Status}
    for status in Status:
        code = "0" if status.ok else "1"
        assert rows[status.value].endswith(code), (status, rows[status.value])


def test_ok_statuses() -> None:
    assert {s.value for s in OK_STATUSES} == {"optimal", "feasible", "simulated"}
    assert status_ok("simulated") and not status_ok("time_limit") and not status_ok("unsupported")


def _scenario(horizon: float) -> dict:
    """One pursuer at the origin and one evader 10 away running straight away: capture at
    (10 − ε)/(u − v) = 9.9/0.5 = 19.8 by the closed form of a pursuer chasing along a line."""
    return {
        "kind": "pursuit_scenario",
        "name": "escape",
        "pursuers": {"positions": [[0.0, 0.0]], "speed": 1.0, "strategy": "pp"},
        "evaders": {"positions": [[10.0, 0.0]], "speed": 0.5, "strategy": {"type": "fixed", "heading": 0.0}},
        "capture_radius": 0.1,
        "time_step": 0.01,
        "horizon": horizon,
    }


def test_an_escape_within_the_horizon_is_a_result_exit_0(cli, tmp_path) -> None:
    path = tmp_path / "escape.yaml"
    path.write_text(yaml.safe_dump(_scenario(horizon=5.0)))
    code, out, err = cli("solve", path, "--json")
    assert code == 0 and "error" not in err
    data = json.loads(out)
    assert data["status"] == "simulated"
    assert data["metrics"]["escaped"] == [0] and data["metrics"]["capture_times"] == [None]
    assert "E1 escaped" in data["message"]


def test_a_finished_scenario_is_simulated_with_its_capture_time() -> None:
    result = gamespec.solve(gamespec.spec_from_dict(_scenario(horizon=30.0)))
    assert result.status is Status.SIMULATED and result.metrics["escaped"] == []
    assert result.t_final == pytest.approx(9.9 / 0.5, abs=2 * 0.01)


def test_pure_evasion_from_one_pure_pursuer_is_optimal_on_analytic() -> None:
    """Proposition 1 with one pursuer: running along the line of sight is the optimum, t_c =
    (r0 − ε)/(u − v); the analytic backend's eq. 2.27 heading is that, and says optimal."""
    spec = gamespec.spec_from_dict(
        {
            "kind": "engagement",
            "pursuers": [{"name": "P1", "position": [0.0, 0.0], "speed": 1.0, "strategy": "pp"}],
            "evader": {"position": [0.0, 2.0], "speed": 0.5},
            "capture_radius": 0.01,
        }
    )
    result = gamespec.solve(spec, "analytic")
    assert result.status is Status.OPTIMAL
    assert result.t_final == pytest.approx((2.0 - 0.01) / 0.5, rel=1e-6)
    assert result.metrics["headings"][0] == pytest.approx(0.5 * 3.141592653589793, abs=1e-6)


def test_two_pure_pursuers_on_analytic_stay_feasible_and_point_to_casadi() -> None:
    result = gamespec.solve(ROOT / "problems/ch2/pure_pursuit_two_on_one.yaml", "analytic")
    assert result.status is Status.FEASIBLE and "casadi" in result.message
