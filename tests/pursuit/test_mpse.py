"""MPSE optimal evasion (§3.2): the capturing set P* and Propositions 5–6."""

from __future__ import annotations

import pytest

import gamespec
from gamespec.pursuit.verification import RESIM_RTOL
from gamespec.studies.capturing_set import check_capturing_set, keep_pursuers
from tests.conftest import PROBLEMS

MPSE_CB = PROBLEMS / "ch3" / "mpse_optimal_evasion_cb.yaml"


@pytest.mark.parametrize("backend", ["analytic", "casadi"])
def test_dropping_pursuers_outside_the_capturing_set_changes_nothing(backend: str) -> None:
    """Prop. 5: the optimal evasion depends only on P*; re-solving with P* alone gives the same
    capture time and the same evader path."""
    check = check_capturing_set(gamespec.load(MPSE_CB), backend)
    assert check.full.ok and check.reduced.ok
    assert 1 <= len(check.capturing_set) < 5
    assert check.reduced.metrics["capturing_set"] == check.capturing_set
    assert check.capture_time_difference < 1e-3 * check.full.t_final
    if backend == "analytic":
        assert check.path_difference < 1e-3


def test_ocp_and_linear_program_agree_on_capture_time_and_capturing_set() -> None:
    """Eq. 3.2 generated for five pursuers, solved by collocation, against the exact program. The
    program uses two headings; the collocated control alternates between them (a relaxed control),
    which re-simulated need not capture at t_f: then the Result may not claim ``optimal``."""
    exact = gamespec.solve(MPSE_CB)
    ocp = gamespec.solve(MPSE_CB, "casadi")
    assert exact.backend == "analytic"
    assert ocp.ok
    if ocp.status == gamespec.Status.OPTIMAL:
        assert ocp.checks["resimulated_capture_time_error"] <= RESIM_RTOL * ocp.t_final
    assert ocp.metrics["capturing_set"] == exact.metrics["capturing_set"]
    assert ocp.t_final == pytest.approx(exact.t_final, rel=1e-3)
    assert ocp.t_final <= exact.t_final * (1 + 1e-6)


def test_dropping_a_capturing_pursuer_changes_the_solution() -> None:
    """The converse that makes the check meaningful: without one pursuer of P* the evader lasts longer."""
    spec = gamespec.load(MPSE_CB)
    full = gamespec.solve(spec, "analytic")
    names = [p.name for p in spec.pursuers if p.name != full.metrics["capturing_set"][0]]
    assert gamespec.solve(keep_pursuers(spec, names), "analytic").t_final > full.t_final + 1e-3


def test_keep_pursuers_rejects_unknown_names() -> None:
    with pytest.raises(gamespec.SpecError, match="no pursuer"):
        keep_pursuers(gamespec.load(MPSE_CB), ["P9"])


def test_proposition_6_pure_pursuit() -> None:
    """Prop. 6 on eqs. 3.15–3.16: a third, distant PP pursuer is outside P* and dropping it leaves
    the capture time and the evader path unchanged."""
    data = gamespec.load(PROBLEMS / "ch2" / "pure_pursuit_two_on_one.yaml").model_dump(mode="json")
    data["pursuers"].append({"name": "P3", "position": [4.0, 4.0], "speed": 1.0, "strategy": "pp"})
    data["method"]["grading"] = 30
    check = check_capturing_set(gamespec.spec_from_dict(data))
    assert check.full.metrics["frame"] == check.reduced.metrics["frame"] == "fixed"
    assert check.capturing_set == ["P1", "P2"]
    assert check.full.checks["max_defect"] < 1e-6
    assert check.capture_time_difference < 1e-6
    assert check.path_difference < 1e-3
