"""Association: IoU and gated Hungarian assignment (scipy's linear_sum_assignment)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.stats import chi2


def iou_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU (len(a), len(b)) of boxes x, y, w, h."""
    a, b = np.asarray(a, float).reshape(-1, 4), np.asarray(b, float).reshape(-1, 4)
    iw = np.minimum(a[:, None, 0] + a[:, None, 2], b[:, 0] + b[:, 2]) - np.maximum(a[:, None, 0], b[:, 0])
    ih = np.minimum(a[:, None, 1] + a[:, None, 3], b[:, 1] + b[:, 3]) - np.maximum(a[:, None, 1], b[:, 1])
    inter = np.maximum(iw, 0) * np.maximum(ih, 0)
    union = (a[:, 2] * a[:, 3])[:, None] + b[:, 2] * b[:, 3] - inter
    return inter / np.maximum(union, 1e-12)


def chi2_gate(dim: int, probability: float = 0.99) -> float:
    """The squared-Mahalanobis gate that a true measurement passes with `probability`."""
    return float(chi2.ppf(probability, dim))


def assign(cost: np.ndarray, max_cost: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Minimum-cost one-to-one assignment with pairs costing more than `max_cost` forbidden.

    Returns (matches (k, 2) row/col pairs, unmatched rows, unmatched cols).
    """
    cost = np.asarray(cost, float)
    n, m = cost.shape
    if n and m:
        allowed = cost <= max_cost
        rows, cols = linear_sum_assignment(np.where(allowed, cost, max_cost + 1e6 + np.abs(cost[allowed]).sum()))
        ok = allowed[rows, cols]
        rows, cols = rows[ok], cols[ok]
    else:
        rows = cols = np.zeros(0, np.intp)
    return (np.stack([rows, cols], axis=1), np.setdiff1d(np.arange(n), rows), np.setdiff1d(np.arange(m), cols))
