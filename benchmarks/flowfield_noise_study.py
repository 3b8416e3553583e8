"""Fig. 5.2: capture probability at T̂ against the noise level α of the linear-flow file, open vs
closed loop (eq. 5.39, with the Monte Carlo and its 95 % interval).

Run: ``python -m benchmarks.flowfield_noise_study [OUT.png]``. One compiled model re-solves for each
α; the reachability stage does not depend on α and is computed once.
"""

from __future__ import annotations

import sys
from pathlib import Path

import gamespec
from gamespec.flowfield.plotting import plot_noise_study
from tests.conftest import PROBLEMS

ALPHAS = (0.05, 0.1, 0.2)


def main() -> None:
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "capture_probability_vs_alpha.png")
    solver = gamespec.compile_spec(PROBLEMS / "ch5" / "linear_flow.yaml", options={"cross_check": False})
    results = [solver.solve(parameters={"alpha": a}) for a in ALPHAS]
    print("| α | open loop (5.39) | closed loop (5.39) | MC open | MC closed | game |")
    print("|---|---|---|---|---|---|")
    for a, r in zip(ALPHAS, results, strict=True):
        m = r.metrics
        mc = m["monte_carlo_capture_probability"]
        print(
            f"| {a} | {m['capture_probability_open_loop']:.4f} | "
            f"{m['capture_probability_closed_loop']:.4f} | "
            f"{mc['open_loop']['estimate']:.4f} | {mc['closed_loop']['estimate']:.4f} | {r.status.value} |"
        )
    print(f"wrote {plot_noise_study(results, 'alpha', out)}")


if __name__ == "__main__":
    main()
