"""Optimal evasion from constant-bearing pursuers (§2.4.1, §3.2.1), as a linear program.

With every pursuer on constant bearing the line-of-sight angles never move, whatever the evader does
(eq. 3.3), so ṙ_i depends on the evader's heading alone (eqs. 2.8, 3.2) and r_i(t) = r_i(0) +
Σ_k s_k ṙ_i(θ_k) when the evader spends time s_k on heading θ_k, in any order. The longest capture
time is therefore the linear program max Σ s_k s.t. Σ_k s_k (−ṙ_i(θ_k)) ≤ r_i(0) − ε, s ≥ 0, over a
grid of headings (refined once around the headings it uses). Its solution uses at most
card(P*) headings. The thesis concludes from eq. 2.15 that the optimal heading is constant; that
holds when the program uses one heading (as in the two-pursuer examples of §2.4.4, where it is the
farther intersection of the two Apollonius circles, Fig. 2.7), but with more pursuers the program
can use two or more headings (H of eq. 3.6 then attains its minimum, zero, at several headings) and
beat every constant heading; :func:`best_constant_heading` keeps the thesis's constant-heading
answer for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import linprog

from gamespec.errors import UnsupportedFeature
from gamespec.pursuit import headings
from gamespec.pursuit.simulation import HeadingLaw, Players

GRID = 1441
"""Headings in the first linear program; the second refines ±2 grid steps around each one used and
the third keeps only the refined headings (merged where adjacent), its durations then scaled to be
exactly feasible (the solver's tolerance aside); the exact best constant heading replaces it when
at least as good. The costates are the duals of a
fourth over the first grid plus those headings, so that they hold for every heading."""


def closing_rate(theta_E: np.ndarray, phi: np.ndarray, u: np.ndarray, v: float) -> np.ndarray:
    """ṙ_i = v cos(θ_E − φ_i) − √(u_i² − v² sin²(θ_E − φ_i)) (eq. 3.2 with the root of eq. 3.3)."""
    a = theta_E - phi
    return v * np.cos(a) - np.sqrt(u**2 - (v * np.sin(a)) ** 2)


def capture_times(players: Players, headings: np.ndarray) -> np.ndarray:
    """Capture times (k, n) of each CB pursuer against constant headings: (r_i(0) − ε) / −ṙ_i."""
    if any(s != "cb" for s in players.strategies):
        raise UnsupportedFeature("the constant-bearing closed form needs every pursuer on cb")
    rate = closing_rate(np.asarray(headings)[:, None], players.los_angles(), players.speeds, players.v)
    return (players.distances() - players.eps) / -rate


def best_constant_heading(players: Players) -> headings.HeadingChoice:
    """The best constant heading against CB pursuers (the thesis's optimum, §2.4.1).

    Degenerate cases come out as pure evasion (θ_E = φ_i, Theorem 1's proof); non-degenerate ones
    as a heading of simultaneous capture.
    """
    return headings.best_constant_heading(lambda h: capture_times(players, h), players.los_angles())


@dataclass(frozen=True)
class EvasionPlan:
    """Headings θ_k held for durations s_k, one after the other; capture at Σ s_k.

    ``costates`` are λ_i = −y_i, y the program's dual values: with them H(θ) = −1 + Σ λ_i ṙ_i(θ)
    (eq. 3.6) is ≥ 0 for every heading and = 0 on the headings used (minimum principle with
    eq. 3.9), and λ_i = 0 for pursuers outside P* (complementary slackness, as in Prop. 5).
    """

    headings: np.ndarray
    durations: np.ndarray
    costates: np.ndarray

    @property
    def capture_time(self) -> float:
        return float(self.durations.sum())

    @property
    def switch_times(self) -> np.ndarray:
        return np.cumsum(self.durations)[:-1]

    def law(self) -> HeadingLaw:
        """The plan as a heading law θ_E(t) (the last heading held after the last switch)."""
        switches = self.switch_times
        return lambda t, P, E: float(self.headings[np.searchsorted(switches, t, side="right")])


def hamiltonian(players: Players, costates: np.ndarray, theta_E: np.ndarray) -> np.ndarray:
    """H = −1 + Σ λ_i ṙ_i(θ_E) (eq. 3.6) at headings ``theta_E``."""
    rates = closing_rate(np.asarray(theta_E)[:, None], players.los_angles(), players.speeds, players.v)
    return -1.0 + rates @ costates


def _program(players: Players, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rates = closing_rate(grid[:, None], players.los_angles(), players.speeds, players.v)
    budget = players.distances() - players.eps
    res = linprog(-np.ones(grid.size), A_ub=-rates.T, b_ub=budget, bounds=(0, None), method="highs")
    used = res.x > 1e-12 * max(budget.max(), 1.0)
    return grid[used], res.x[used], res.ineqlin.marginals


def optimal_evasion(players: Players) -> EvasionPlan:
    """The evader's optimal plan against CB pursuers: the linear program of the module doc."""
    if any(s != "cb" for s in players.strategies):
        raise UnsupportedFeature("the constant-bearing closed form needs every pursuer on cb")
    coarse = np.linspace(-np.pi, np.pi, GRID, endpoint=False)
    step = coarse[1] - coarse[0]
    used, *_ = _program(players, coarse)
    fine = np.unique(np.concatenate([np.linspace(h - 2 * step, h + 2 * step, 81) for h in used]))
    heads, durations, _ = _program(players, fine)
    clusters = np.split(np.arange(heads.size), np.flatnonzero(np.diff(heads) > step) + 1)
    merged = np.array([np.average(heads[c], weights=durations[c]) for c in clusters])
    heads, durations, _ = _program(players, merged)
    *_, duals = _program(players, np.union1d(coarse, merged))
    closing = -closing_rate(heads[:, None], players.los_angles(), players.speeds, players.v).T @ durations
    durations = durations * np.min((players.distances() - players.eps) / closing)
    constant = best_constant_heading(players)
    if constant.capture_time >= durations.sum():
        return EvasionPlan(np.array([constant.heading]), np.array([constant.capture_time]), duals)
    return EvasionPlan(np.angle(np.exp(1j * heads)), durations, duals)
