"""Monte Carlo of the nonlinear SDE eq. 5.1 with the game's feedback applied (Euler–Maruyama).

The diffusion is taken at the left point of each substep (Itô, as Euler–Maruyama); the drift is
averaged over the substep with a Heun predictor (its ``O(dt)`` bias in the mean would otherwise
show in the capture probability: ε is small against the drift over T̂). For a uniform flow the
scheme is exact.

Both agents follow ``dxⁱ = (uⁱ + f(xⁱ)) dt + g(xⁱ) dwⁱ`` with ``u_k = v_k + K_k y_k`` held over each
step (eq. 5.27). The players build ``y`` as section 5.3 says they can: from the observed positions
and the previous controls, ``y_{k+1} = A_k y_k + (x_{k+1} − A_k x_k − B_k u_k − r_k)``, i.e. eq. 5.28
with the noise term ``D_k w_k`` read off the discrete model eq. 5.7. All samples advance together;
the normal draws come from :func:`gamespec.montecarlo.sample` (seeded).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gamespec.flowfield.budget import UNLIMITED, Budget
from gamespec.flowfield.field import FlowField
from gamespec.flowfield.linearize import DiscreteModel
from gamespec.montecarlo import Normal, sample


@dataclass(frozen=True)
class Ensemble:
    """Sample paths ``positions`` (samples, N+1, 4) on the step times, pursuer then evader."""

    positions: np.ndarray

    def separation(self) -> np.ndarray:
        """``‖xᵖ_k − xᵉ_k‖`` (samples, N+1)."""
        return np.linalg.norm(self.positions[..., :2] - self.positions[..., 2:], axis=-1)


def simulate(
    field: FlowField,
    model: DiscreteModel,
    x0: np.ndarray,
    V: np.ndarray,
    K: np.ndarray,
    samples: int,
    seed: int,
    substeps: int = 5,
    budget: Budget = UNLIMITED,
) -> Ensemble | None:
    """``samples`` paths with ``substeps`` steps per control step; the ``budget`` counts each
    control step (its progress line) and, past its time limit, stops the paths (None)."""
    N, dt = model.N, model.step / substeps
    noise = sample({"w": Normal(0.0, 1.0, shape=(N, substeps, 2, 2))}, samples, seed)["w"]
    x = np.tile(np.asarray(x0, dtype=float), (samples, 1))
    y = np.zeros_like(x)
    out = [x]
    for k in range(N):
        u = V[k] + y @ K[k].T
        start = x
        for j in range(substeps):
            agents = x.reshape(samples, 2, 2)
            kick = (
                np.einsum("saij,saj->sai", field.diffusion(agents), noise[:, k, j]) * np.sqrt(dt)
            ).reshape(samples, 4)
            drift = field.drift(agents).reshape(samples, 4)
            guess = x + (u + drift) * dt + kick
            x = (
                x
                + (u + (drift + field.drift(guess.reshape(samples, 2, 2)).reshape(samples, 4)) / 2) * dt
                + kick
            )
        y = y @ model.A[k].T + (x - start @ model.A[k].T - u @ model.B[k].T - model.r[k])
        out.append(x)
        budget.advance(f"Monte Carlo, step {k + 1} of {N}")
        if budget.expired():
            return None
    return Ensemble(np.stack(out, axis=1))
