"""Seed 000 (Wan, Wang, Yuan 2011): JPDA with Murty's K best joint events, for video multi-target tracking.

The association core. A joint event assigns each target at most one measurement and each measurement
at most one target (the rest are clutter); in the standard parametric form of the paper's eq. 8,
P(event) is proportional to the product over associated pairs (t, j) of P_D g_tj / lambda and over
unassociated targets of (1 - P_D), with g_tj the Gaussian innovation likelihood and lambda the clutter
density. Eq. 9 sums these into beta. Exactly, every joint event is enumerated (exponential in the
cluster size); the paper instead takes the K most probable events, found by Murty's algorithm on the
assignment problem whose cost is -log of those factors, with one dummy "missed" column per target.
"""

from __future__ import annotations

import numpy as np

from .assignment import murty


def _factors(g, pd, clutter_density) -> tuple[np.ndarray, np.ndarray]:
    """Per-pair detection factors P_D g / lambda (n, m) and per-target miss factors 1 - P_D (n,), validated."""
    g = np.asarray(g, float)
    if g.ndim != 2 or not np.isfinite(g).all() or (g < 0).any():
        raise ValueError(f"g must be a finite, non-negative (targets, measurements) matrix, got shape {g.shape}")
    pd = np.broadcast_to(np.asarray(pd, float), (g.shape[0],))
    if ((pd < 0) | (pd > 1)).any():
        raise ValueError(f"pd must lie in [0, 1], got {pd.tolist()}")
    if not clutter_density > 0:
        raise ValueError(f"clutter_density must be positive, got {clutter_density!r}")
    return pd[:, None] * g / clutter_density, 1.0 - pd


def _all_events(w: np.ndarray, miss: np.ndarray) -> list[tuple[list[int], float]]:
    """Every joint event with a nonzero weight: (measurement of each target or -1, weight)."""
    n, m = w.shape
    events = []

    def extend(t: int, chosen: list[int], used: set[int], weight: float):
        if t == n:
            events.append((list(chosen), weight))
            return
        if miss[t] > 0:
            extend(t + 1, chosen + [-1], used, weight * miss[t])
        for j in np.flatnonzero(w[t]).tolist():
            if j not in used:
                extend(t + 1, chosen + [j], used | {j}, weight * w[t, j])

    extend(0, [], set(), 1.0)
    return events


def _best_events(w: np.ndarray, miss: np.ndarray, k: int) -> list[tuple[list[int], float]]:
    """The k most probable joint events (Murty on -log factors), weights relative to the best."""
    n, m = w.shape
    with np.errstate(divide="ignore"):
        cost = np.full((n, m + n), np.inf)
        cost[:, :m] = -np.log(w)
        cost[np.arange(n), m + np.arange(n)] = -np.log(miss)
    best = murty(cost, k)
    if not best:
        return []
    low = best[0][1]
    return [(np.where(cols < m, cols, -1).tolist(), float(np.exp(low - total))) for cols, total in best]


def association_probabilities(g, pd, clutter_density: float, k: int | None = None) -> np.ndarray:
    """beta (n_targets, m + 1): beta[t, 0] the probability that no measurement is target t's, beta[t, j + 1] that
    measurement j is. g (n, m) Gaussian likelihoods, 0 where gated out; pd scalar or per target; k=None enumerates
    every joint event, an int uses the k best from Murty (renormalised)."""
    w, miss = _factors(g, pd, clutter_density)
    n, m = w.shape
    if k is not None and (not isinstance(k, (int, np.integer)) or k < 1):
        raise ValueError(f"k must be None (exact) or a positive integer, got {k!r}")
    events = _all_events(w, miss) if k is None else _best_events(w, miss, int(k))
    total = sum(weight for _, weight in events)
    if not total > 0:
        raise ValueError("no joint event has a nonzero probability (pd = 1 and a target without a gated measurement?)")
    beta = np.zeros((n, m + 1))
    rows = np.arange(n)
    for chosen, weight in events:
        beta[rows, np.asarray(chosen, int) + 1] += weight
    return beta / total
