"""The verdicts and tolerances of graded checks, where the status policy reads them."""

from __future__ import annotations

from typing import Any

import numpy as np


def verdicts(checks: dict[str, tuple[float | None, float]]) -> dict[str, dict[str, Any]]:
    """``checks_passed`` (a value that is a finite number at most its tolerance) and
    ``check_tolerances`` for the checks that have a tolerance (the status policy reads them)."""
    passed = {
        name: value is not None and bool(np.isfinite(value)) and value <= tolerance
        for name, (value, tolerance) in checks.items()
    }
    return {"checks_passed": passed, "check_tolerances": {n: t for n, (_, t) in checks.items()}}
