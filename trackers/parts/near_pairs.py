"""Sort-and-sweep search for the pairs of points that lie near each other, without an n x m matrix."""

from __future__ import annotations

import numpy as np


def near_in_x_and_y(centre: np.ndarray, reach: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (k, j) with |points[j] - centre[k]| <= reach[k] in x and in y; centre, reach (n, 2), points (M, 2).

    The candidates of an exact test that implies both bounds (a Mahalanobis gate: a squared distance is at least
    dx^2 / var_x, so reach sqrt(limit var); ipf's conflict set: the reach its sizes and ratio allow). A sweep over the
    points sorted by x finds them in O((n + M) log M + pairs) instead of n x M.
    """
    order = np.argsort(points[:, 0], kind="stable")
    xs = points[order, 0]
    lo = np.searchsorted(xs, centre[:, 0] - reach[:, 0], side="left")
    count = np.searchsorted(xs, centre[:, 0] + reach[:, 0], side="right") - lo
    k = np.repeat(np.arange(len(centre)), count)
    j = order[np.arange(len(k)) - np.repeat(np.cumsum(count) - count - lo, count)]
    ok = np.abs(points[j, 1] - centre[k, 1]) <= reach[k, 1]
    return k[ok], j[ok]
