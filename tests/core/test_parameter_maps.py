"""Runtime parameters through the parameter maps (cvxpy's ``apply_parameters``): for every shipped
file whose chain has transforms, a re-solve of one compiled model at random parameter points equals
a fresh compile at those points, and the mapped chain hands the backend what re-applying the
transforms would.

The points are seeded per file: every runtime parameter of the file moved by up to
:data:`SPREAD` of its value, a draw the spec's own validation refuses (a pursuer no faster than the
evader, a start inside the capture radius) drawn again, so every point lies in the valid range.
Both sides start IPOPT from the spec's own starting point (``warm_start: false``; the engagement
transform passes its guess anyway), so the answers agree to round-off when the maps are right; the
Monte Carlo analyses of the chapter-6 rewrites are set to 0 samples, as they do not take part.
"""

from __future__ import annotations

import zlib
from pathlib import Path

import numpy as np
import pytest
import yaml

import gamespec
from gamespec import solving
from gamespec.errors import SpecError
from gamespec.loader import with_values
from gamespec.solving import build_steps
from tests.conftest import PROBLEMS
from tests.core.test_chain import MAX_RANGE, _with_transforms, test_transforms  # noqa: F401 (a fixture)

POINTS = 10
SPREAD = 0.05
COLD = {"warm_start": False}
CHAINED_KINDS = ("engagement", "multiphase_optimal_control")


def _chained(path: Path) -> bool:
    """Whether a shipped file reaches the casadi backend through transforms (read as data only)."""
    data = yaml.safe_load(path.read_text())
    backend = (data.get("solver") or {}).get("backend", "casadi")
    return backend == "casadi" and (data.get("kind") in CHAINED_KINDS or bool(data.get("transforms")))


FILES = sorted(p for p in PROBLEMS.rglob("*.yaml") if _chained(p))
FAST = {"double_integrator_two_phases.yaml"}
"""The file whose 10 fresh compiles stay within a few seconds (the rest are ``slow``)."""
COSTLY_GUESS = {"relay_pure_pursuit.yaml", "constant_bearing_degenerate.yaml"}
"""Files whose guess heading takes seconds to find (48 headings integrated; a degenerate search)."""


def _no_monte_carlo(path: Path) -> list[str]:
    """Overrides that switch off the Monte Carlo of each requested transform that has one."""
    data = yaml.safe_load(path.read_text())
    return [
        f"transforms.{i}.{name}.monte_carlo.samples=0"
        for i, entry in enumerate(data.get("transforms") or [])
        for name, options in entry.items()
        if "monte_carlo" in (options or {})
    ]


def points(spec, count: int, seed: int) -> list[dict[str, float]]:
    """``count`` valid random points of ``spec``'s runtime parameters (see module doc)."""
    rng = np.random.default_rng(seed)
    nominal = spec.runtime_parameters()
    found, refused = [], []
    while len(found) < count:
        point = {n: v * (1 + SPREAD * rng.uniform(-1, 1)) for n, v in nominal.items()}
        try:
            with_values(spec, point)
        except SpecError as err:
            refused.append(str(err))
            assert len(refused) < 20 * count, f"{len(refused)} random points refused, the last: {err}"
            continue
        found.append(point)
    return found


CASES = [pytest.param(p, id=p.stem, marks=() if p.name in FAST else pytest.mark.slow) for p in FILES]
MAPS = [pytest.param(p, id=p.stem, marks=pytest.mark.slow if p.name in COSTLY_GUESS else ()) for p in FILES]


def test_every_chained_file_is_covered() -> None:
    """The files below are the shipped ones with a transform chain (engagements, phases, the
    chapter-6 rewrites) and runtime parameters; the fast ones are among them."""
    assert {p.name for p in FILES} >= FAST
    kinds = {yaml.safe_load(p.read_text())["kind"] for p in FILES}
    assert kinds == {"engagement", "multiphase_optimal_control", "optimal_control"}


@pytest.mark.parametrize("path", CASES)
def test_resolve_after_parameter_map_equals_a_fresh_compile(path: Path) -> None:
    spec = gamespec.load(path, _no_monte_carlo(path))
    solver = gamespec.compile_spec(spec, options=COLD)
    assert solver.steps and spec.runtime_parameters()
    for point in points(spec, POINTS, zlib.crc32(path.name.encode())):
        again = solver.solve(parameters=point)
        fresh = gamespec.compile_spec(with_values(spec, point), options=COLD).solve()
        assert again.status == fresh.status, point
        if fresh.objective is None:
            assert again.objective is None
            continue
        assert again.objective == pytest.approx(fresh.objective, rel=1e-8), point
        assert again.parameters == fresh.parameters


@pytest.mark.parametrize("path", MAPS)
def test_mapped_chain_hands_the_backend_what_reapplying_would(path: Path, monkeypatch) -> None:
    """The last target's runtime values (what the compiled model gets) and its structure (what it
    was built from) are those of the transforms applied afresh, and no transform is re-applied."""
    spec = gamespec.load(path, _no_monte_carlo(path))
    solver = gamespec.compile_spec(spec)
    news = [with_values(spec, p) for p in points(spec, 3, zlib.crc32(path.name.encode()) + 1)]
    expected = [build_steps(new, solver.backend)[-1].target for new in news]

    def refused(*args, **kwargs):
        raise AssertionError("a transform was re-applied")

    monkeypatch.setattr(solving, "_applied", refused)
    for new, fresh in zip(news, expected, strict=True):
        target = solver.mapped_steps(new, names=list(new.runtime_parameters()))[-1].target
        assert target.runtime_parameters() == pytest.approx(fresh.runtime_parameters(), rel=1e-12)
        assert target.structure() == fresh.structure()
    assert expected[0].runtime_parameters() != expected[1].runtime_parameters()


@pytest.mark.usefixtures("test_transforms")
def test_a_transform_without_a_map_is_reapplied(tmp_path, monkeypatch) -> None:
    """``weighted_lagrange`` has no parameter map (every parameter unmapped): a new ``rho`` re-applies
    it, once per re-solve, and the re-solve still equals a fresh compile."""
    file = _with_transforms(MAX_RANGE, tmp_path, [{"weighted_lagrange": {"term": "-u**2", "weight": 0.2}}])
    solver = gamespec.compile_spec(file, options=COLD)
    applied = []
    real = solving._applied
    monkeypatch.setattr(solving, "_applied", lambda *a, **k: applied.append(a[0].name) or real(*a, **k))
    again = solver.solve(parameters={"rho": 9.0})
    assert applied == ["weighted_lagrange"]
    fresh = gamespec.compile_spec(gamespec.load(file, ["problem.parameters.rho=9"]), options=COLD).solve()
    assert again.status == fresh.status == gamespec.Status.OPTIMAL
    assert again.objective == pytest.approx(fresh.objective, rel=1e-8)
