"""Seeded draws of named distributions, plain random or by Latin hypercube (McKay et al., 1979).

Both methods draw one block of uniforms of width ``Σ dimension`` and hand each distribution its
columns, in the order the mapping lists them, so a draw depends only on ``(distributions, n, seed,
method)`` — never on how a later run is batched or which executor runs it.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from gamespec.montecarlo.distributions import Distribution

METHODS = ("random", "latin_hypercube")

_TINY = np.finfo(float).tiny


def _uniforms(n: int, width: int, seed: int, method: str) -> np.ndarray:
    """``(n, width)`` uniforms strictly inside (0, 1), so inverse CDFs stay finite."""
    if method == "random":
        u = np.random.default_rng(seed).random((n, width))
    elif method == "latin_hypercube":
        from scipy.stats import qmc  # scipy.stats costs a command's start-up ~0.5 s: imported when used

        u = qmc.LatinHypercube(d=width, seed=np.random.default_rng(seed)).random(n)
    else:
        raise ValueError(f"unknown sampling method {method!r}; expected one of {', '.join(METHODS)}")
    return np.clip(u, _TINY, np.nextafter(1.0, 0.0))


def sample(
    distributions: Mapping[str, Distribution], n: int, seed: int, method: str = "random"
) -> dict[str, np.ndarray]:
    """``n`` seeded draws of each named distribution, as ``{name: array (n, *shape)}``.

    With ``method="latin_hypercube"`` every scalar coordinate is stratified: each of its ``n`` equal
    probability bins holds exactly one draw.
    """
    if n < 1:
        raise ValueError(f"n must be a positive number of samples, got {n}")
    width = sum(d.dimension for d in distributions.values())
    u = _uniforms(n, max(width, 1), seed, method)
    out: dict[str, np.ndarray] = {}
    start = 0
    for name, dist in distributions.items():
        out[name] = dist.from_uniform(u[:, start : start + dist.dimension])
        start += dist.dimension
    return out
