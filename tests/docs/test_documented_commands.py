"""Every documented command runs and ends as its claim says (docs/contributing.md): the commands are
collected from the problem files' comments, README.md and docs/ by :mod:`tests.docs.commands`."""

from __future__ import annotations

import pytest

from tests.docs.commands import (
    DEFAULT_BUDGET_CPU_S,
    SLOW_CPU_S,
    ClaimError,
    Command,
    Figure,
    Outcome,
    documented_commands,
    mismatches,
    parse_claim,
    run_line,
    workspace,
)

COMMANDS = documented_commands()


def _slow(command: Command) -> bool:
    """A command is slow when it, or a command it needs first, is tagged slow."""
    return any(c.claim is not None and c.claim.slow for c in [command, *command.needs])


def _param(command: Command):
    claim = command.claim
    marks = []
    if _slow(command):
        marks.append(pytest.mark.slow)
    if claim is not None and claim.not_run:
        marks.append(pytest.mark.skip(reason=f"not run: {claim.not_run}"))
    return pytest.param(command, id=command.id, marks=marks)


def test_every_command_has_a_claim() -> None:
    assert len(COMMANDS) >= 40
    unclaimed = [c.id for c in COMMANDS if c.claim is None]
    assert not unclaimed, f"commands without a '→' claim on the next line: {unclaimed}"


def test_claims_record_their_cpu_and_the_default_suite_stays_small() -> None:
    claims = [c.claim for c in COMMANDS if c.claim is not None and c.claim.not_run is None]
    assert all(claim.cpu_s is not None for claim in claims), "every claim records its CPU time"
    assert all(claim.slow == (claim.cpu_s >= SLOW_CPU_S) for claim in claims), "slow means ≥ SLOW_CPU_S"
    quick = [c for c in COMMANDS if c.claim is not None and c.claim.not_run is None and not _slow(c)]
    assert sum(n.claim.cpu_s for c in quick for n in [c, *c.needs]) <= DEFAULT_BUDGET_CPU_S


@pytest.mark.parametrize("command", [_param(c) for c in COMMANDS])
def test_documented_command(command: Command, tmp_path) -> None:
    with workspace(tmp_path):
        for needed in command.needs:
            assert not mismatches(needed, run_line(needed)), f"{needed.id}, which {command.id} needs"
        outcome = run_line(command)
    assert not mismatches(command, outcome), (command.text, outcome.stderr[-2000:])


def test_claim_syntax() -> None:
    claim = parse_claim(" optimal, t_final = 25.4 (± 0.1), metrics.x.y = 2 (± 5 %)  [slow, 38 s CPU]", "here")
    assert claim.status == "optimal" and claim.exit_code == 0 and claim.slow and claim.cpu_s == 38.0
    assert claim.figures == (Figure("t_final", 25.4, 0.1), Figure("metrics.x.y", 2.0, 0.05, relative=True))
    assert parse_claim("locally_infeasible  [1.5 s CPU]", "here").exit_code == 1
    assert parse_claim("exit 2  [0.4 s CPU]", "here").exit_code == 2
    assert (
        parse_claim("feasible, metrics.solution_concept = lower_value", "here")
        .figures[0]
        .holds("lower_value")
    )
    assert parse_claim("not run: needs a cluster", "here").not_run == "needs a cluster"
    for wrong in ("fine", "optimal, t_final = 2", "exit two", "exit 0, t_final = 1 (± 1)", "not run:"):
        with pytest.raises(ClaimError, match="here"):
            parse_claim(wrong, "here")


def test_figures_and_outcomes() -> None:
    figure = Figure("t_final", 10.0, 0.1)
    assert figure.holds(10.05) and not figure.holds(10.2) and not figure.holds(None)
    assert not figure.holds(float("nan")) and not figure.holds(True)
    assert Figure("x", 100.0, 0.02, relative=True).holds(101.9)
    command = Command(
        "f", 1, "gamespec solve f", [["solve", "f"]], parse_claim("optimal, a.b = 1 (± 0)", "f"), "f"
    )
    good = Outcome([0], {"status": "optimal", "a": {"b": 1}}, 0.0, "")
    assert not mismatches(command, good)
    assert mismatches(command, Outcome([1], {"status": "infeasible", "a": {"b": 1}}, 0.0, ""))
    assert mismatches(command, Outcome([0], {"status": "optimal", "a": {"b": 2}}, 0.0, ""))
