"""The chapter 6 files from the command line: weights by ``--set``, the transformed spec, bad requests."""

from __future__ import annotations

import json

import yaml

from tests.desensitize.helpers import FINAL, FIXED, SEYWALD


def test_set_changes_the_weight(cli) -> None:
    code, out, _ = cli("solve", FIXED, "--set", "problem.parameters.s1_final=0.04", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["status"] == "optimal"
    assert abs(data["metrics"]["final_sensitivity"]["S_x1_rho"] - 0.04) < 1e-8
    assert data["metrics"]["monte_carlo"]["samples"] == 2000


def test_show_transformed_prints_the_sensitivity_equations(cli) -> None:
    code, out, _ = cli("show", FINAL, "--transformed")
    assert code == 0
    problem = yaml.safe_load(out)["problem"]
    assert problem["dynamics"]["S_x1_rho"] == "S_x2_rho*rho + x2"  # eq. 6.24
    assert problem["dynamics"]["S_x2_rho"] == "0"
    assert "S_x1_rho_f**2*alpha" in problem["objective"]["mayer"]


def test_bad_requests_exit_2_naming_the_field(cli, tmp_path) -> None:
    data = yaml.safe_load(SEYWALD.read_text())
    data["transforms"][0]["desensitize"]["method"] = "seywal"
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(data))
    code, _, err = cli("validate", bad)
    assert code == 2 and "transforms.0.desensitize.method" in err
    data["transforms"][0]["desensitize"].update(method="seywald", trajectory={"S_x3_rho": "alpha"})
    bad.write_text(yaml.safe_dump(data))
    code, _, err = cli("solve", bad)
    assert code == 2 and "trajectory.S_x3_rho: unknown entry" in err
