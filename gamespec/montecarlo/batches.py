"""Run a function over Monte Carlo draws in batches, serially or through any ``map``-like callable.

The function receives one batch ``{name: array (b, *shape)}`` and returns ``{output: array (b, ...)}``;
a cheap vectorized function takes large batches, an expensive per-sample one (a solve) small ones, so
an executor can spread them. Batches are cut from draws made once up front
(:func:`gamespec.montecarlo.sample`), so the outputs do not depend on the batch size or the mapper.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import TypeAlias

import numpy as np

Batch: TypeAlias = dict[str, np.ndarray]
BatchFunction: TypeAlias = Callable[[Batch], Mapping[str, np.ndarray]]
Mapper: TypeAlias = Callable[[BatchFunction, Sequence[Batch]], Iterable[Mapping[str, np.ndarray]]]
"""``map(function, batches)`` returning one output per batch, in order (builtin ``map``,
``concurrent.futures.Executor.map``, or a studies executor's ``map``)."""


def split(samples: Mapping[str, np.ndarray], batch_size: int) -> list[Batch]:
    """Consecutive row slices of the draws, ``batch_size`` rows each (the last one may be shorter)."""
    if batch_size < 1:
        raise ValueError(f"batch_size must be positive, got {batch_size}")
    sizes = {len(v) for v in samples.values()}
    if len(sizes) != 1:
        raise ValueError("every sampled variable needs the same number of draws")
    (n,) = sizes
    return [{k: v[i : i + batch_size] for k, v in samples.items()} for i in range(0, n, batch_size)]


def run(
    function: BatchFunction,
    samples: Mapping[str, np.ndarray],
    batch_size: int,
    mapper: Mapper = map,
) -> dict[str, np.ndarray]:
    """Outputs of ``function`` for all draws, batches joined back in sample order."""
    batches = split(samples, batch_size)
    outputs = list(mapper(function, batches))
    if not outputs:
        return {}
    names = list(outputs[0])
    for batch, out in zip(batches, outputs, strict=True):
        rows = len(next(iter(batch.values())))
        if list(out) != names or any(len(out[k]) != rows for k in names):
            raise ValueError("each batch must return the same outputs, one row per draw")
    return {k: np.concatenate([np.asarray(out[k]) for out in outputs]) for k in names}
