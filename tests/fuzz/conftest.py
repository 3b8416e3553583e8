"""Hypothesis profiles of the fuzz suite and the exit-code histogram in the pytest summary.

``fast`` (the default) keeps the suite in the default run, derandomized: every run (CI's included)
tries the same inputs, so the suite's verdict is reproducible. ``HYPOTHESIS_PROFILE=long`` tries many
more inputs per strategy, new ones each run (run before submitting; the summary gives the count and
the histogram): it is where new bad inputs are found.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

from tests.fuzz.harness import EXIT_CODES

_COMMON = {
    "deadline": None,
    "suppress_health_check": [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
}
settings.register_profile("fast", max_examples=25, derandomize=True, **_COMMON)
settings.register_profile("long", max_examples=1500, derandomize=False, **_COMMON)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "fast"))


def pytest_terminal_summary(terminalreporter) -> None:
    if EXIT_CODES:
        histogram = ", ".join(f"exit {code}: {n}" for code, n in sorted(EXIT_CODES.items()))
        profile = os.environ.get("HYPOTHESIS_PROFILE", "fast")
        terminalreporter.write_line(
            f"fuzz ({profile} profile): {sum(EXIT_CODES.values())} inputs; {histogram}"
        )
