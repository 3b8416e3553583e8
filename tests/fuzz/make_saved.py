"""Write the seeds of the saved-input fuzz (``tests/fuzz/saved/``): one small saved Result per kind
(and per figure a kind draws differently) and three study stores (a sweep, a compare, a Table 2.1
study), each from a shipped problem file made small with ``--set``.

Run from the repository root after a change to what a kind saves: ``python -m tests.fuzz.make_saved``
(a minute). The fuzz (:mod:`tests.fuzz.test_saved`) tampers with copies of these.
"""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

from gamespec.cli import run

HERE = Path(__file__).resolve().parent / "saved"
ROOT = HERE.parents[2]

RESULTS = {
    "optimal_control": ("ch2/one_on_one_pure_evasion.yaml", []),
    "multiphase_optimal_control": ("ocp/double_integrator_two_phases.yaml", []),
    "desensitized": (
        "ch6/zermelo_trajectory_desensitized.yaml",
        ["transforms.0.desensitize.monte_carlo.samples=20", "method.intervals=8"],
    ),
    "rcs": ("ch6/rcs_single_obstacle.yaml", ["method.intervals=10"]),
    "engagement": ("ch2/pure_pursuit_two_on_one.yaml", []),
    "engagement_relay": ("ch2/relay_pure_pursuit.yaml", []),
    "pursuit_scenario": ("ch3/mpse_five_on_one_cb.yaml", []),
    "lq_stochastic_game": ("ch4/test_example.yaml", ["method.monte_carlo.samples=20"]),
    "flow_field_game": (
        "ch5/linear_flow.yaml",
        ["method.grid.nodes=[56,46]", "method.monte_carlo.samples=20", "method.max_time=4"],
    ),
    "differential_game": ("ch7/asymmetric_obstacle.yaml", []),
    "differential_game_open_loop": ("ch7/lq_pursuit_evasion.yaml", []),
    "pursuit_suboptimal_study": (
        "ch2/pure_pursuit_suboptimal_study.yaml",
        ["speeds=[0.4,0.6]", "grid.angles=2", "grid.fractions=1"],
    ),
    "rcs_multi_obstacle_study": (
        "ch6/rcs_multi_obstacle_study.yaml",
        [
            "obstacles=[2]",
            "alphas=[0.0,1.0]",
            "guesses=[4.0]",
            "samples=20",
            "steps=50",
            "method.intervals=10",
        ],
    ),
}


def _cli(*args: str) -> None:
    code = run([str(a) for a in args])
    if code != 0:
        sys.exit(f"gamespec {' '.join(map(str, args))} exited {code}")


def main() -> None:
    shutil.rmtree(HERE, ignore_errors=True)
    scratch = HERE / "scratch"
    for name, (file, overrides) in RESULTS.items():
        sets = [a for o in [*overrides, f"store={scratch / name}"] for a in ("--set", o)]
        if "study" not in name:
            sets = [a for o in overrides for a in ("--set", o)]
        _cli("solve", ROOT / "problems" / file, *sets, "--out", HERE / "results" / name, "--json")
    shutil.move(scratch / "pursuit_suboptimal_study", HERE / "stores" / "table_2_1")
    shutil.rmtree(scratch)
    evasion = ROOT / "problems" / "ch2" / "one_on_one_pure_evasion.yaml"
    _cli(
        "sweep",
        evasion,
        "--param",
        "v=0.3,0.5",
        "--param",
        "u=1,1.5",
        "--out",
        HERE / "stores" / "sweep",
        "--json",
    )
    _cli("compare", evasion, "--backends", "casadi", "--out", HERE / "stores" / "compare", "--json")
    for wal in HERE.glob("stores/*/store.sqlite-*"):
        wal.unlink()


if __name__ == "__main__":
    main()
