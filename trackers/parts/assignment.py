"""Association: IoU, chi-square gates, clusters of gated pairs, gated Hungarian assignment and Murty's k-best
assignments (scipy)."""

from __future__ import annotations

import heapq

import lap
import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.special import chdtri


def corners(tlwh: np.ndarray) -> np.ndarray:
    """Boxes x, y, w, h -> x1, y1, x2, y2."""
    return np.concatenate([tlwh[:, :2], tlwh[:, :2] + tlwh[:, 2:4]], axis=1)


def corner_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU (len(a), len(b)) of boxes x1, y1, x2, y2, computed as the SORT reference code does."""
    w = np.maximum(0.0, np.minimum(a[:, None, 2], b[:, 2]) - np.maximum(a[:, None, 0], b[:, 0]))
    h = np.maximum(0.0, np.minimum(a[:, None, 3], b[:, 3]) - np.maximum(a[:, None, 1], b[:, 1]))
    wh = w * h
    area_a, area_b = (a[:, 2] - a[:, 0]) * (a[:, 3] - a[:, 1]), (b[:, 2] - b[:, 0]) * (b[:, 3] - b[:, 1])
    return wh / (area_a[:, None] + area_b - wh)


def paired_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU of corner boxes a[i] and b[i], row by row."""
    wh = np.clip(np.minimum(a[:, 2:], b[:, 2:]) - np.maximum(a[:, :2], b[:, :2]), 0, None)
    inter = wh[:, 0] * wh[:, 1]
    area = lambda c: (c[:, 2] - c[:, 0]) * (c[:, 3] - c[:, 1])
    return inter / (area(a) + area(b) - inter)


def plus_one_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU (len(a), len(b)) of boxes x1, y1, x2, y2 counting pixels inclusively (a box from 0 to 9 is 10 wide), as
    cython_bbox's bbox_overlaps computes it for ByteTrack."""
    ax1, ay1, ax2, ay2 = a.T[:, :, None]
    bx1, by1, bx2, by2 = b.T
    iw = np.minimum(ax2, bx2) - np.maximum(ax1, bx1) + 1
    ih = np.minimum(ay2, by2) - np.maximum(ay1, by1) + 1
    inter = iw * ih
    overlap = (iw > 0) & (ih > 0)
    union = (ax2 - ax1 + 1) * (ay2 - ay1 + 1) + (bx2 - bx1 + 1) * (by2 - by1 + 1) - inter
    return np.where(overlap, inter / np.where(overlap, union, 1.0), 0.0)


def lapjv(cost: np.ndarray, limit: float = np.inf) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(matches (k, 2) sorted by row, unmatched rows, unmatched cols) of the minimum-cost assignment of a rectangular
    `cost`, where leaving a row or a column unassigned costs limit / 2: what lap.lapjv(cost, extend_cost=True,
    cost_limit=limit) finds, as the SORT and ByteTrack reference codes call it. It is `lap` that is called (not
    scipy), because among equal-cost assignments the reference outputs depend on the one it picks."""
    n, m = cost.shape
    if not cost.size:
        return np.zeros((0, 2), np.intp), np.arange(n), np.arange(m)
    x, y = lap.lapjv(cost, extend_cost=True, return_cost=False, **({} if np.isinf(limit) else {"cost_limit": limit}))
    matched = x >= 0
    rows = matched.nonzero()[0]
    pairs = np.empty((len(rows), 2), np.intp)
    pairs[:, 0], pairs[:, 1] = rows, x[matched]
    return pairs, (~matched).nonzero()[0], (y < 0).nonzero()[0]


def chi2_gate(dim: int, probability: float = 0.99) -> float:
    """The squared-Mahalanobis gate that a true measurement passes with `probability`."""
    return float(chdtri(dim, 1.0 - probability))  # chi2.ppf(probability, dim), without importing scipy.stats


def clusters(gated: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cluster labels of targets (rows) and measurements (columns) linked by gated pairs (connected components)."""
    n, m = gated.shape
    rows, cols = np.nonzero(gated)
    graph = coo_matrix((np.ones(len(rows)), (rows, n + cols)), shape=(n + m, n + m))
    labels = connected_components(graph, directed=False)[1]
    return labels[:n], labels[n:]


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


def _best(cost: np.ndarray) -> tuple[np.ndarray, float] | None:
    """The minimum-cost full row assignment of `cost` (inf = forbidden) and its total, or None if none is
    feasible."""
    try:
        rows, cols = linear_sum_assignment(cost)
    except ValueError:  # scipy: "cost matrix is infeasible"
        return None
    total = float(cost[rows, cols].sum())
    return (cols, total) if np.isfinite(total) else None  # an inf term (costs are never -inf or NaN) makes it inf


def murty(cost: np.ndarray, k: int) -> list[tuple[np.ndarray, float]]:
    """The k lowest-cost assignments of every row of `cost` (n, m), n <= m, to a distinct column.

    Murty's algorithm (as used by Cox and Hingorani 1996): the best assignment's solution space is
    partitioned into subproblems, each forcing the solution's first i pairs and forbidding pair i;
    the cheapest open subproblem gives the next assignment. np.inf marks forbidden pairs. Returns
    (cols, total cost) pairs in ascending order of cost; fewer than k if fewer are feasible.
    """
    cost = np.asarray(cost, float)
    if cost.ndim != 2 or cost.shape[0] > cost.shape[1]:
        raise ValueError(f"murty: cost must be (n, m) with n <= m, got shape {cost.shape}")
    if np.isnan(cost).any() or (cost == -np.inf).any():
        raise ValueError("murty: cost must not contain NaN or -inf (use +inf for forbidden pairs)")
    n = cost.shape[0]
    if k <= 0:
        return []
    if n == 0:
        return [(np.zeros(0, np.intp), 0.0)]
    first = _best(cost)
    if first is None:
        return []
    heap = [(first[1], 0, first[0], cost)]
    earlier = np.tri(n, k=-1, dtype=bool)  # [i, j]: row j comes before row i
    out, counter = [], 1
    while heap and len(out) < k:
        total, _, cols, node = heapq.heappop(heap)
        out.append((cols, total))
        forced = node.copy()
        # row i's open columns once rows 0..i-1 are forced: its own, less those that rows 0..i-1 took
        finite = np.isfinite(node)
        alternatives = (finite.sum(axis=1) - (finite[:, cols] & earlier).sum(axis=1)).tolist()
        for i in range(n):
            if alternatives[i] > 1:  # a row with one open column (forced, or left so) has no alternative
                child = forced.copy()
                child[i, cols[i]] = np.inf
                sol = _best(child)
                if sol is not None:
                    heapq.heappush(heap, (sol[1], counter, sol[0], child))
                    counter += 1
            keep = forced[i, cols[i]]
            forced[i, :], forced[:, cols[i]] = np.inf, np.inf
            forced[i, cols[i]] = keep
        # Only k - len(out) more are popped, each no dearer than the cheapest that many now open (children never
        # cost less than their parent): dearer subproblems can go, which bounds the memory to about 2k matrices.
        # Pruning only once the heap holds twice that many keeps its cost (a selection over the heap) from growing
        # as k^2; the pops, ordered by (cost, counter), are the same whenever it prunes.
        remaining = k - len(out)
        if len(heap) > 2 * remaining > 0:
            limit = heapq.nsmallest(remaining, heap)[-1][0]
            heap = [node for node in heap if node[0] <= limit]
            heapq.heapify(heap)
    return out
