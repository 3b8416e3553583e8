"""Whether an OCP solution mapped back to an engagement is its optimum, not only a KKT point.

An ``optimal`` status from the NLP only says that a KKT point of the discretized problem was found;
:func:`verify` accepts it as the engagement's optimum when, in addition, the re-simulated capture
time is no earlier than the guess heading's (which the evader can always achieve), agrees with the
solution's t_f within :data:`RESIM_RTOL`, and the Hamiltonian (eq. 2.23: constant along an optimal
path) varies by at most :data:`HAMILTONIAN_TOL`.
"""

from __future__ import annotations

from gamespec.result import Result

HAMILTONIAN_TOL = 1e-2
"""Largest variation of H along a solution (eq. 2.23) that :func:`verify` accepts as optimal."""

RESIM_RTOL = 1e-3
"""Largest |re-simulated capture time − t_f| / t_f that :func:`verify` accepts as optimal; also the
relative margin by which the re-simulated capture may fall short of the guess heading's."""


def verify(result: Result, guess_capture_time: float) -> str | None:
    """The first check (see module doc) a mapped-back ``result`` fails, None if it passes;
    ``guess_capture_time`` is the capture time of the guess heading."""
    checks, t_f = result.checks, result.t_final
    resimulated = checks.get("resimulated_capture_time")
    if resimulated is None:
        return "the re-simulated evader is not captured"
    if resimulated < guess_capture_time * (1 - RESIM_RTOL):
        return (
            f"re-simulated capture time {resimulated:.6g} is earlier than the guess heading's "
            f"{guess_capture_time:.6g}"
        )
    if abs(resimulated - t_f) > RESIM_RTOL * t_f:
        return f"re-simulated capture time {resimulated:.6g} is not within {RESIM_RTOL:g} of t_f = {t_f:.6g}"
    variation = checks.get("hamiltonian_variation")
    if variation is not None and variation > HAMILTONIAN_TOL:
        return f"hamiltonian_variation {variation:.3g} exceeds {HAMILTONIAN_TOL:g} (eq. 2.23)"
    return None
