"""One Monte Carlo engine for every study: seeded samplers, batched runs, summaries with intervals.

A numerics layer: it knows nothing of specs, solvers or executors. ``distributions`` holds the
samplers (each maps uniform draws to its own, by the inverse CDF), ``sampling`` draws them plainly
or by Latin hypercube, ``batches`` runs a function over the draws in batches (serially, or through
any ``map``-like callable, e.g. an executor's), ``summary`` reduces outputs to means with confidence
intervals and event counts to Wilson intervals.
"""

from gamespec.montecarlo.batches import Mapper, run
from gamespec.montecarlo.distributions import Distribution, MultivariateNormal, Normal, Uniform
from gamespec.montecarlo.sampling import METHODS, sample
from gamespec.montecarlo.summary import Proportion, Summary, proportion, summarize

__all__ = [
    "METHODS",
    "Distribution",
    "Mapper",
    "MultivariateNormal",
    "Normal",
    "Proportion",
    "Summary",
    "Uniform",
    "proportion",
    "run",
    "sample",
    "summarize",
]
