"""Results a user can take away: the table of a study folder, CSV and Parquet that read back to the
stored values, and plots of a sweep and of a compare."""

from __future__ import annotations

import csv
import json
import math

import pyarrow.parquet as pq
import pytest

from gamespec.studies.export import study_rows
from gamespec.studies.store import ResultStore
from tests.conftest import PROBLEMS

SWEEP = PROBLEMS / "ch2" / "one_on_one_pure_evasion.yaml"


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """A 3 × 2 sweep, solved once for the module."""
    from gamespec.cli import run

    out = tmp_path_factory.mktemp("sweep")
    assert run(["sweep", str(SWEEP), "--param", "v=0.3:0.5:3", "--param", "u=1,1.5", "--out", str(out)]) == 0
    return out


def _same(a, b) -> bool:
    if isinstance(a, float) and math.isnan(a):
        return isinstance(b, float) and math.isnan(b)
    return a == b


def test_csv_and_parquet_read_back_to_the_stored_rows(cli, swept, tmp_path) -> None:
    csv_path, parquet_path = tmp_path / "sweep.csv", tmp_path / "sweep.parquet"
    code, out, err = cli("results", swept, "--csv", csv_path, "--parquet", parquet_path)
    assert code == 0, err
    assert "0.4" in out and "optimal" in out
    rows = study_rows(ResultStore(swept))
    assert len(rows) == 6
    assert [(r["v"], r["u"]) for r in rows] == sorted((r["v"], r["u"]) for r in rows)

    table = pq.read_table(parquet_path).to_pylist()
    assert len(table) == len(rows)
    for stored, read in zip(rows, table, strict=True):
        assert all(_same(stored.get(k), read[k]) for k in read)

    with csv_path.open() as handle:
        read_csv = list(csv.DictReader(handle))
    for stored, read in zip(rows, read_csv, strict=True):
        assert read["key"] == stored["key"] and read["status"] == stored["status"]
        assert float(read["t_final"]) == stored["t_final"]
        assert float(read["v"]) == stored["v"] and read["spec_hash"] == stored["spec_hash"]


def test_results_as_json_carry_provenance(cli, swept) -> None:
    code, out, _ = cli("results", swept, "--json")
    rows = json.loads(out)
    assert code == 0 and len(rows) == 6
    assert all(r["versions.gamespec"] and r["spec_hash"] and r["created"] for r in rows)


def test_plot_draws_a_sweep_against_each_parameter(cli, swept, tmp_path) -> None:
    code, _, err = cli("plot", swept, "--out", tmp_path)
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.glob("*.png")) == ["sweep_u.png", "sweep_v.png"]


def test_compare_is_stored_tabled_and_plotted(cli, tmp_path) -> None:
    code, _, err = cli("compare", SWEEP, "--backends", "casadi,pyomo", "--out", tmp_path)
    assert code == 0, err
    code, out, err = cli("results", tmp_path, "--json")
    rows = {r["backend"]: r for r in json.loads(out)}
    assert set(rows) == {"casadi", "pyomo"}
    assert rows["pyomo"]["t_final"] == pytest.approx(rows["casadi"]["t_final"], rel=1e-6)
    code, _, err = cli("plot", tmp_path)
    assert code == 0, err
    assert (tmp_path / "compare.png").exists()


def test_results_of_a_folder_without_a_study_is_exit_2(cli, tmp_path) -> None:
    code, _, err = cli("results", tmp_path)
    assert code == 2 and "no study results here" in err and err.count("\n") == 1


def test_plot_of_a_desensitized_sweep_adds_the_tradeoff(cli, tmp_path) -> None:
    path = PROBLEMS / "ch6" / "zermelo_final_state_desensitized.yaml"
    code, _, err = cli("sweep", path, "--param", "alpha=0,75", "--out", tmp_path)
    assert code == 0, err
    code, _, err = cli("plot", tmp_path)
    assert code == 0, err
    assert (tmp_path / "sweep_alpha.png").exists() and (tmp_path / "tradeoff.png").exists()
