"""A study kind's point store lands under ``--out`` (``OUT/points``), not in the file's
``./runs/...`` whatever ``--out`` says (issue 28 item 5); ``--set store=...`` still decides."""

from __future__ import annotations

from gamespec.studies.export import find_store
from tests.conftest import PROBLEMS

STUDY = PROBLEMS / "ch2" / "pure_pursuit_suboptimal_study.yaml"
ONE_POINT = ["--set", "grid.angles=1", "--set", "grid.fractions=1", "--set", "speeds=[0.5]"]


def test_a_study_store_lands_under_out(cli, tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out"
    code, _, err = cli("solve", STUDY, *ONE_POINT, "--out", out)
    assert code == 0, err
    assert find_store(out).folder == out / "points"
    assert len(find_store(out).items()) == 1
    assert not (tmp_path / "runs").exists()
    code, table, err = cli("results", out / "points")
    assert code == 0 and "1 points" in table, err


def test_set_store_still_decides(cli, tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    code, _, err = cli("solve", STUDY, *ONE_POINT, "--set", "store=mine", "--out", tmp_path / "out")
    assert code == 0, err
    assert find_store(tmp_path / "mine").items() and not (tmp_path / "out" / "points").exists()
