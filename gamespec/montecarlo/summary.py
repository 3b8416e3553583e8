"""Sample statistics with intervals: a Student-t interval for a mean, a Wilson interval for a
proportion (Wilson, 1927)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Summary:
    """Mean, spread, range and a confidence interval for the mean of one output.

    Non-finite values (a failed sample) are left out and counted in ``failures``.
    """

    n: int
    failures: int
    mean: float
    std: float
    min: float
    max: float
    ci_low: float
    ci_high: float
    confidence: float


@dataclass(frozen=True)
class Proportion:
    """An event frequency ``successes / n`` with its Wilson score interval."""

    successes: int
    n: int
    estimate: float
    low: float
    high: float
    confidence: float


def _check_confidence(confidence: float) -> None:
    if not 0.0 < confidence < 1.0:
        raise ValueError(f"confidence must lie in (0, 1), got {confidence}")


def _summary(values: np.ndarray, confidence: float) -> Summary:
    flat = np.asarray(values, dtype=float).reshape(-1)
    finite = flat[np.isfinite(flat)]
    n = finite.size
    nan = float("nan")
    if n == 0:
        return Summary(0, flat.size, nan, nan, nan, nan, nan, nan, confidence)
    mean = float(finite.mean())
    std = float(finite.std(ddof=1)) if n > 1 else nan
    from scipy.stats import t  # scipy.stats costs a command's start-up ~0.5 s: imported when used

    half = float(t.ppf(0.5 + confidence / 2, n - 1)) * std / math.sqrt(n) if n > 1 else nan
    return Summary(
        n=n,
        failures=flat.size - n,
        mean=mean,
        std=std,
        min=float(finite.min()),
        max=float(finite.max()),
        ci_low=mean - half,
        ci_high=mean + half,
        confidence=confidence,
    )


def summarize(outputs: Mapping[str, np.ndarray], confidence: float = 0.95) -> dict[str, Summary]:
    """Per output: ``mean ± t_{(1+c)/2, n−1} · s / √n`` over its finite samples, with std, min, max."""
    _check_confidence(confidence)
    return {name: _summary(values, confidence) for name, values in outputs.items()}


def proportion(events: np.ndarray, confidence: float = 0.95) -> Proportion:
    """Frequency of true ``events`` with the Wilson interval
    ``(p̂ + z²/2n ± z √(p̂(1−p̂)/n + z²/4n²)) / (1 + z²/n)``."""
    _check_confidence(confidence)
    flags = np.asarray(events, dtype=bool).reshape(-1)
    n = flags.size
    if n == 0:
        raise ValueError("proportion needs at least one event")
    k = int(flags.sum())
    p = k / n
    from scipy.stats import norm  # imported when used (see _summary)

    z = float(norm.ppf(0.5 + confidence / 2))
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return Proportion(k, n, p, max(0.0, centre - half), min(1.0, centre + half), confidence)
