"""``gamespec reproduce``: the shipped manifest is valid and names files that load; on a small
manifest, the table's rows, verdicts and files; the full report in the slow suite."""

from __future__ import annotations

import csv

import pytest
import yaml

import gamespec
from gamespec.commands.reproduction import COLUMNS, Experiment, load_manifest, verdict
from tests.conftest import PROBLEMS

# eq. 2.2: pure evasion from P1, t_c = (d - eps) / (u1 - v) with the file's d = 1, eps = 0.001,
# u1 = 1, v = 0.5 (the analytic backend's closed form is checked against simulation elsewhere).
CLOSED_FORM = (1.0 - 0.001) / (1.0 - 0.5)


def _row(name: str, **fields: object) -> dict[str, object]:
    return {
        "name": name,
        "chapter": 2,
        "title": name,
        "file": "ch2/constant_bearing_degenerate.yaml",
        "backend": "analytic",
        "metric": "t_final",
        "reference": "eq. 2.2",
        **fields,
    }


SMALL = [
    _row("closed_form", thesis=CLOSED_FORM, tolerance=1e-6),
    _row("wrong_value", thesis=CLOSED_FORM + 0.5, tolerance=1e-6, reason="a deliberately wrong value"),
    _row("no_reason", thesis=CLOSED_FORM - 0.5, tolerance=1e-6),
    _row("under_a_number", statement="before t = 2", below=2.0),
    _row("above_itself", statement="after closed_form", above="closed_form"),
    _row("withheld", thesis="withheld"),
]


def test_small_manifest(cli, tmp_path) -> None:
    manifest = tmp_path / "manifest.yaml"
    manifest.write_text(yaml.safe_dump({"experiments": SMALL}))
    out = tmp_path / "report"
    code, stdout, err = cli(
        "reproduce", "--manifest", manifest, "--out", out, "--problems", PROBLEMS, "--chapter", "2"
    )
    assert code == 0, err
    assert "[1/1] ch2/constant_bearing_degenerate.yaml" in err  # one solve for six rows, progress on stderr
    with (out / "reproduce.csv").open() as handle:
        rows = {row["experiment"]: row for row in csv.DictReader(handle)}
    assert list(rows) == [r["name"] for r in SMALL] and list(next(iter(rows.values()))) == list(COLUMNS)
    verdicts = {name: row["verdict"] for name, row in rows.items()}
    assert verdicts == {
        "closed_form": "holds",
        "wrong_value": "differs",
        "no_reason": "differs",
        "under_a_number": "holds",
        "above_itself": "differs",
        "withheld": "withheld",
    }
    assert rows["wrong_value"]["reason"] == "a deliberately wrong value"
    assert rows["no_reason"]["reason"] == "no reason recorded"
    assert rows["withheld"]["thesis"] == "withheld"
    assert abs(float(rows["closed_form"]["gamespec"]) - CLOSED_FORM) < 1e-5
    assert "--backend analytic" in rows["closed_form"]["file"]
    markdown = (out / "reproduce.md").read_text().splitlines()
    assert len(markdown) == 2 + len(SMALL) and all(name in stdout for name in ("closed_form", "differs"))
    saved = out / "closed_form"
    assert gamespec.Result.load(saved).status is gamespec.Status.OPTIMAL
    assert list(saved.glob("*.png")), "figures are drawn from the saved Result"


def test_chapter_filter_and_missing_metric(cli, tmp_path) -> None:
    manifest = tmp_path / "manifest.yaml"
    rows = [_row("missing", metric="metrics.no_such_number"), _row("elsewhere", chapter=7)]
    manifest.write_text(yaml.safe_dump({"experiments": rows}))
    out = tmp_path / "report"
    code, _, err = cli(
        "reproduce", "--manifest", manifest, "--out", out, "--problems", PROBLEMS, "--chapter", "2"
    )
    assert code == 1 and "missing" in err.splitlines()[-1]
    with (out / "reproduce.csv").open() as handle:
        (row,) = csv.DictReader(handle)
    assert row["verdict"] == "failed" and "metrics.no_such_number" in row["reason"]


def test_verdict_rules() -> None:
    one = Experiment.model_validate(_row("one", thesis=1.0, tolerance=0.1))
    assert verdict(one, 1.05, {}) == "holds" and verdict(one, 1.2, {}) == "differs"
    assert verdict(one, None, {}) == "failed" and verdict(one, float("nan"), {}) == "failed"
    ordered = Experiment.model_validate(_row("two", above="one"))
    assert verdict(ordered, 2.0, {"one": 1.0}) == "holds" and verdict(ordered, 0.5, {"one": 1.0}) == "differs"
    assert verdict(ordered, 2.0, {"one": None}) == "differs"
    assert verdict(Experiment.model_validate(_row("three")), 2.0, {}) == "no thesis value"


def test_manifest_refuses_unknown_rows(tmp_path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump({"experiments": [_row("a", above="nobody")]}))
    with pytest.raises(gamespec.SpecError, match="nobody"):
        load_manifest(bad)


def test_shipped_manifest_files_load() -> None:
    """Every experiment of the shipped manifest names a problem file and overrides that validate."""
    experiments = load_manifest().experiments
    assert {e.chapter for e in experiments} >= {2, 5, 6, 7}
    for e in experiments:
        gamespec.load(PROBLEMS / e.file, e.set)


@pytest.mark.slow
def test_full_reproduction(cli, tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)  # the Table 2.1 study keeps its store relative to the current folder
    out = tmp_path / "report"
    code, _, err = cli("reproduce", "--out", out, "--problems", PROBLEMS)
    assert code == 0, err
    with (out / "reproduce.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [r["experiment"] for r in rows] == [e.title for e in load_manifest().experiments]
    assert all(r["verdict"] != "failed" for r in rows)
    unexplained = [r["experiment"] for r in rows if r["reason"] == "no reason recorded"]
    assert not unexplained, f"the manifest gives no reason why these differ from the thesis: {unexplained}"
