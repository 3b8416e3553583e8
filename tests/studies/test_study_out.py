"""A study kind's point store lands under ``--out`` (``OUT/points``), not in the file's relative
``./runs/.../points`` whatever ``--out`` says (issue 28 item 5); an absolute store is kept."""

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


def test_an_absolute_store_is_kept(cli, tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    mine = tmp_path / "mine"
    code, _, err = cli("solve", STUDY, *ONE_POINT, "--set", f"store={mine}", "--out", tmp_path / "out")
    assert code == 0, err
    assert find_store(mine).items() and not (tmp_path / "out" / "points").exists()
