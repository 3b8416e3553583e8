"""A study's table shows its parameters and the headline numbers of its points' kind
(:attr:`gamespec.registry.Kind.columns`): a chapter-5 sweep's capture probabilities, not only the
objective and t_final (issue 28 item 1)."""

from __future__ import annotations

import pytest

from gamespec import registry
from gamespec.studies.export import headline_columns, study_rows
from gamespec.studies.store import ResultStore
from tests.conftest import PROBLEMS
from tests.plots import fixtures


@pytest.fixture
def chapter5_sweep(tmp_path):
    """A sweep store over α whose points are the saved ``linear_flow`` Result, as
    :func:`gamespec.studies.sweep.solve_point` stores a point."""
    result = fixtures.saved(PROBLEMS / "ch5/linear_flow.yaml")
    store = ResultStore(tmp_path)
    store.set_meta("study", {"type": "sweep", "problem": result.problem, "parameters": ["alpha"]})
    for alpha in (0.1, 0.2):
        value = {"alpha": alpha, **result.summary(), "metrics": result.metrics}
        store.put(f"levelset/x:alpha={alpha}", value)
    return tmp_path, result


def test_a_chapter_5_sweep_table_shows_its_capture_probabilities(cli, chapter5_sweep) -> None:
    folder, result = chapter5_sweep
    code, out, err = cli("results", folder)
    assert code == 0, err
    header = next(line for line in out.splitlines() if "alpha" in line)
    m = result.metrics
    for name, value in [
        ("capture_probability_open_loop", m["capture_probability_open_loop"]),
        ("capture_probability_closed_loop", m["capture_probability_closed_loop"]),
        ("capture_time", m["capture_time"]),
    ]:
        assert f"metrics.{name}" in header
        assert f"{value:.6g}" in out, name


def test_headline_columns_are_the_kinds_own_where_the_rows_have_them(chapter5_sweep) -> None:
    folder, _ = chapter5_sweep
    rows = study_rows(ResultStore(folder))
    shown = headline_columns(rows)
    declared = registry.kind("flow_field_game").columns
    assert shown == [c for c in declared if all(c in row for row in rows)]
    assert "metrics.capture_probability_open_loop" in shown
    assert headline_columns([{"kind": "no_such_kind", "metrics.x": 1.0}]) == []
