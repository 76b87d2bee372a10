"""Box geometry every stage shares (the sensor, calibration, scoring): boxes are x, y, w, h rows.

IoU, union boxes, centres, the id lookup, the thresholded Hungarian matching, the check of one frame's ids and
boxes, clipping to the image, the pairs that overlap, and the visible fraction of people standing on a ground plane.
The bottom layer of both sources: it imports only numpy and scipy.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

EPS = np.finfo(float).eps  # TrackEval's tolerance for thresholds and empty boxes


def overlap(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(intersection area, area of a, area of b) of boxes a[..., i] and b[..., i], broadcasting over the leading axes."""
    ax, ay, aw, ah = (a[..., k] for k in range(4))
    bx, by, bw, bh = (b[..., k] for k in range(4))
    iw = np.minimum(ax + aw, bx + bw) - np.maximum(ax, bx)
    ih = np.minimum(ay + ah, by + bh) - np.maximum(ay, by)
    return np.maximum(iw, 0) * np.maximum(ih, 0), aw * ah, bw * bh


def pair_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU of boxes a[..., i] and b[..., i], broadcasting over the leading axes, in their own dtype; TrackEval's guard:
    0 where either box has no area (at most EPS)."""
    inter, area_a, area_b = overlap(a, b)
    union = area_a + area_b - inter
    empty_a, empty_b = area_a <= EPS, area_b <= EPS
    if empty_a.any() or empty_b.any():  # only then can the union vanish
        inter = np.where(empty_a | empty_b | (union <= EPS), 0.0, inter)
        union = np.where(union <= EPS, 1.0, union)
    return inter / union


def box_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU matrix (len(a), len(b)) of every pair of boxes, in float64 (TrackEval's box IoU)."""
    a, b = np.asarray(a, float).reshape(-1, 4), np.asarray(b, float).reshape(-1, 4)
    return pair_iou(a[:, None], b[None])


def union_boxes(boxes: np.ndarray, groups: np.ndarray, n_groups: int) -> np.ndarray:
    """(n_groups, 4) float64: the smallest box holding every box of each group (`groups`: each box's group index)."""
    lo = np.full((2, n_groups), np.inf)
    hi = np.full((2, n_groups), -np.inf)
    for axis in (0, 1):  # one-dimensional ufunc.at has a fast path (about 40x the two-dimensional one)
        np.minimum.at(lo[axis], groups, boxes[:, axis])
        np.maximum.at(hi[axis], groups, boxes[:, axis] + boxes[:, 2 + axis])
    return np.concatenate([lo, hi - lo]).T


def centres(boxes: np.ndarray) -> np.ndarray:
    """(n, 2) float64 box centres."""
    boxes = np.asarray(boxes, float).reshape(-1, 4)
    return boxes[:, :2] + boxes[:, 2:] / 2


def centre_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Euclidean distance matrix (len(a), len(b)) between box centres."""
    return np.linalg.norm(centres(a)[:, None] - centres(b)[None], axis=2)


def rows_of(ids: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """Row of each wanted id in `ids` (unique), or -1."""
    if not len(ids):
        return np.full(len(wanted), -1)
    order = np.argsort(ids)
    pos = np.minimum(np.searchsorted(ids, wanted, sorter=order), len(ids) - 1)
    return np.where(ids[order[pos]] == wanted, order[pos], -1)


def match(similarity: np.ndarray, threshold: float, bonus: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(rows, columns) of the Hungarian assignment maximising the summed score (similarity, plus `bonus` where given)
    over the pairs whose similarity is at least `threshold`, inclusive and exact: TrackEval's rule `>= 0.5` is
    threshold = 0.5 - EPS. An assigned pair scoring at most EPS (one below the threshold) is left unmatched."""
    score = similarity if bonus is None else similarity + bonus
    score = np.where(similarity < threshold, 0.0, score)
    rows, cols = linear_sum_assignment(score, maximize=True)
    keep = score[rows, cols] > EPS
    return rows[keep], cols[keep]


def check_frame(what: str, ids, boxes, where: str, positive: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(ids int64 (n,), boxes float64 (n, 4)) of one frame, or a ValueError "{where}: {what} ..." naming the problem
    (and the first bad row): ids 1-D integers, unique; boxes (n, 4), finite and, with `positive`, of positive width
    and height. Nothing at all (any empty shapes) is n = 0."""
    ids, boxes = np.asarray(ids), np.asarray(boxes, dtype=float)
    if ids.size == 0 and boxes.size == 0:
        return np.zeros(0, np.int64), np.zeros((0, 4))
    if ids.ndim != 1 or boxes.shape != (len(ids), 4):
        raise ValueError(f"{where}: {what} ids must have shape (n,) and boxes (n, 4), got {ids.shape} and {boxes.shape}")
    if ids.dtype.kind not in "iu":
        raise ValueError(f"{where}: {what} ids must be integers, got dtype {ids.dtype}")
    if not np.isfinite(boxes).all():
        raise ValueError(f"{where}: {what} boxes must be finite; row {int(np.flatnonzero(~np.isfinite(boxes).all(1))[0])} is not")
    if positive and not (boxes[:, 2:] > 0).all():
        raise ValueError(f"{where}: {what} boxes must have a positive width and height; row "
                         f"{int(np.flatnonzero(~(boxes[:, 2:] > 0).all(1))[0])} does not")
    if len(set(ids.tolist())) != len(ids):
        raise ValueError(f"{where}: {what} ids must be unique within a frame")
    return ids.astype(np.int64), boxes


def clip_boxes(boxes: np.ndarray, width: int, height: int) -> np.ndarray:
    """Boxes (n, 4) x, y, w, h clipped to the image; fully outside boxes get zero size."""
    boxes = np.asarray(boxes, np.float64)  # float32 corners would round x + w
    corners = np.concatenate([boxes[:, :2], boxes[:, :2] + boxes[:, 2:]], axis=1)
    np.clip(corners, 0, (width, height, width, height), out=corners)
    corners[:, 2:] -= corners[:, :2]
    return corners


def occlusion_visibility(boxes: np.ndarray, width: int, height: int, grid: tuple[int, int] = (8, 16)) -> np.ndarray:
    """Visible fraction of each box x, y, w, h of people on a ground plane: a box whose bottom edge is lower stands
    nearer and hides what it covers, and the image border hides what lies outside. Measured on a grid of points (8
    across, 16 down) in each box: the share that lies in the image and that no nearer box covers."""
    n = len(boxes)
    if not n:
        return np.zeros(0)
    u = (np.arange(grid[0]) + 0.5) / grid[0]
    v = (np.arange(grid[1]) + 0.5) / grid[1]
    px = (boxes[:, 0, None] + boxes[:, 2, None] * u).repeat(grid[1], axis=1)  # (n, points)
    py = np.tile(boxes[:, 1, None] + boxes[:, 3, None] * v, grid[0])
    bottom = boxes[:, 1] + boxes[:, 3]
    seen = (px >= 0) & (px < width) & (py >= 0) & (py < height)
    for i, j in zip(*overlapping_pairs(boxes)):  # each pair once: the nearer box hides part of the farther one
        near, far = (i, j) if bottom[i] > bottom[j] else (j, i)
        if bottom[near] == bottom[far]:
            continue
        b = boxes[near]
        seen[far] &= ~((px[far] >= b[0]) & (px[far] < b[0] + b[2]) & (py[far] >= b[1]) & (py[far] < b[1] + b[3]))
    return seen.mean(axis=1)


def overlapping_pairs(boxes: np.ndarray, margin: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs (i, j), i != j, each pair once, of boxes x, y, w, h that intersect or come within `margin`.

    Sort and sweep along x, then test y on the candidate pairs: O(n log n + pairs) instead of an n x n matrix.
    """
    n = len(boxes)
    order = np.argsort(boxes[:, 0], kind="stable")
    b = boxes[order]
    end = np.searchsorted(b[:, 0], b[:, 0] + b[:, 2] + margin, side="left")
    counts = np.maximum(end - np.arange(n) - 1, 0)
    k = np.repeat(np.arange(n), counts)
    l = k + 1 + np.arange(len(k)) - np.repeat(np.cumsum(counts) - counts, counts)
    ok = (b[k, 1] < b[l, 1] + b[l, 3] + margin) & (b[l, 1] < b[k, 1] + b[k, 3] + margin)
    return order[k[ok]], order[l[ok]]
