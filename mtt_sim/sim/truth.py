"""Ground truth of one frame, measured from the label map.

A target that nothing is drawn over and that lies wholly inside the image is fully visible, and
its box is exact geometry. Only the others (overlapped by something drawn later, or cut by the
image border) are measured on the label map, inside their own box: visible pixels over the pixels
the target would cover alone, the bounding box of the visible pixels, and the connected pieces the
visible region falls into. That keeps the cost proportional to the number of occlusions.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from mtt_sim.sim.render import draw_blob, draw_fixed, fixed_point


@dataclass(frozen=True)
class Truth:
    """Ground truth of the targets inside the image at one frame (rows aligned)."""

    ids: np.ndarray            # (n,) int64, unique over the episode
    boxes: np.ndarray          # (n, 4) float32, full extent x, y, w, h clipped to the image
    visibility: np.ndarray     # (n,) float32 in [0, 1]: visible pixels / pixels of the unoccluded shape in the image
    visible_boxes: np.ndarray  # (n, 4) float32, extent of the visible pixels (zeros where none)
    depth: np.ndarray          # (n,) float32, larger = nearer the viewer
    labels: np.ndarray         # (n,) int, the value of this target in the label map
    pieces: np.ndarray         # (p, 5) float32: row index into these arrays, x, y, w, h of each visible piece
                               # of a target whose visible region falls apart (all pieces of such a target)

    def __len__(self) -> int:
        return len(self.ids)


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


def _covered(boxes: np.ndarray, depth: np.ndarray, over_boxes: np.ndarray, over_depth: np.ndarray) -> np.ndarray:
    """Which of `boxes` intersect another of `boxes`, or one of `over_boxes`, drawn after them (greater depth)."""
    i, j = overlapping_pairs(np.concatenate([boxes, over_boxes]))
    d = np.concatenate([depth, over_depth])
    lower = np.where(d[i] < d[j], i, np.where(d[j] < d[i], j, -1))
    covered = np.zeros(len(d) + 1, bool)
    covered[lower] = True
    return covered[: len(boxes)]


def measure(labels: np.ndarray, ids: np.ndarray, boxes: np.ndarray, depth: np.ndarray, is_rect: np.ndarray,
            occluder_boxes: np.ndarray, occluder_depth: np.ndarray,
            reference: tuple[np.ndarray, np.ndarray] | None = None) -> Truth:
    """Truth for targets with drawn image boxes `boxes` (slot order, label = slot + 1). A frame drawn and then warped
    into the image (a warping camera) gives its `reference`: the boxes as drawn (slot order) and the warp of their
    pixels into the image's, so that a target's unoccluded shape is warped as its label pixels were."""
    h, w = labels.shape
    clipped = clip_boxes(boxes, w, h)
    inside = np.flatnonzero((clipped[:, 2] > 0) & (clipped[:, 3] > 0))
    boxes, clipped, depth = boxes[inside], clipped[inside], depth[inside]
    n = len(inside)
    visibility = np.ones(n, np.float32)
    visible = clipped.astype(np.float32)
    truncated = (clipped[:, 2] < boxes[:, 2] - 1e-9) | (clipped[:, 3] < boxes[:, 3] - 1e-9)
    suspects = np.flatnonzero(truncated | _covered(boxes, depth, occluder_boxes, occluder_depth))
    lo = clipped[suspects, :2].astype(int)
    hi = np.minimum(np.ceil(clipped[suspects, :2] + clipped[suspects, 2:]).astype(int) + 1, (w, h))
    if reference is None:
        local = boxes[suspects].copy()
        local[:, :2] -= lo  # each suspect's shape in its own region of interest
        geometry = fixed_point(local)
    rect = is_rect[inside[suspects]].tolist()
    pieces = []
    for k, (r, (x0, y0), (x1, y1)) in enumerate(zip(suspects.tolist(), lo.tolist(), hi.tolist())):
        mine = cv2.compare(labels[y0:y1, x0:x1], int(inside[r] + 1), cv2.CMP_EQ)
        seen = cv2.countNonZero(mine)
        if reference is None:
            alone = np.zeros(mine.shape, np.uint8)
            draw_fixed(alone, geometry, k, rect[k], 255)
        else:
            alone = _warped_shape(reference[0][inside[r]], rect[k], reference[1], x0, y0, mine.shape)
        full = cv2.countNonZero(alone)
        visibility[r] = min(1.0, seen / full) if full else 0.0
        if not seen:
            visible[r] = 0
            continue
        bx, by, bw, bh = cv2.boundingRect(mine)
        visible[r] = (x0 + bx, y0 + by, bw, bh)
        if seen >= full:
            continue
        count, _, stats, _ = cv2.connectedComponentsWithStats(mine, connectivity=8)
        big = stats[1:, cv2.CC_STAT_AREA] >= max(4, 0.05 * seen)
        if count > 2 and big.sum() >= 2:
            s = stats[1:][big]
            pieces.append(np.column_stack([np.full(len(s), r), s[:, 0] + x0, s[:, 1] + y0, s[:, 2], s[:, 3]]))
    return Truth(ids=ids[inside].astype(np.int64), boxes=clipped.astype(np.float32), visibility=visibility,
                 visible_boxes=visible.astype(np.float32), depth=depth.astype(np.float32),
                 labels=inside + 1, pieces=np.concatenate(pieces).astype(np.float32) if pieces else np.zeros((0, 5), np.float32))



def _warped_shape(box: np.ndarray, is_rect: bool, warp: np.ndarray, x0: int, y0: int, shape: tuple) -> np.ndarray:
    """The pixels (255) that a target drawn as `box` covers alone once `warp` (drawn pixels to image pixels) takes it
    into the image, in the image region of `shape` whose top-left pixel is (x0, y0); nearest neighbour, as the label
    map is warped."""
    bx, by = int(np.floor(box[0])) - 1, int(np.floor(box[1])) - 1
    drawn = np.zeros((int(np.ceil(box[3])) + 3, int(np.ceil(box[2])) + 3), np.uint8)
    draw_blob(drawn, (box[0] - bx, box[1] - by, box[2], box[3]), is_rect, 255)
    lin = warp[:, :2]
    local = np.c_[lin, lin @ (bx, by) + warp[:, 2] - (x0, y0)]
    return cv2.warpAffine(drawn, local, (shape[1], shape[0]), flags=cv2.INTER_NEAREST, borderMode=cv2.BORDER_CONSTANT,
                          borderValue=0)
