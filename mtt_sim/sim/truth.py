"""Ground truth of one frame, measured from the label map.

A target that nothing is drawn over and that lies wholly inside the image is fully visible, and
its box is exact geometry. Only the others (overlapped by something drawn later, or cut by the
image border) are measured on the label map, inside their own box: visible pixels over the pixels
the target would cover alone, the bounding box of the visible pixels, and the connected pieces the
visible region falls into. That keeps the cost proportional to the number of occlusions. The `Truth` type itself
lives below both sources, in `mtt_sim.core.frame`.
"""

from __future__ import annotations

import cv2
import numpy as np

from mtt_sim import boxes as box_geometry
from mtt_sim.boxes import clip_boxes, overlapping_pairs
from mtt_sim.core.frame import Truth
from mtt_sim.core.moved import moved
from mtt_sim.sim.render import draw_blob, draw_fixed, fixed_point

__getattr__ = moved(__name__, box_geometry, "occlusion_visibility")  # deprecated: import it from mtt_sim.boxes


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
        s = pieces_of(mine, seen, (bx, by, bw, bh))
        if len(s):
            pieces.append(np.column_stack([np.full(len(s), r), s[:, 0] + x0, s[:, 1] + y0, s[:, 2], s[:, 3]]))
    return Truth(ids=ids[inside].astype(np.int64), boxes=clipped.astype(np.float32), visibility=visibility,
                 visible_boxes=visible.astype(np.float32), depth=depth.astype(np.float32),
                 labels=inside + 1, pieces=np.concatenate(pieces).astype(np.float32) if pieces else np.zeros((0, 5), np.float32))


def pieces_of(mask: np.ndarray, seen: int, rect: tuple[int, int, int, int]) -> np.ndarray:
    """The boxes (x, y, w, h in `mask`'s pixels) of the connected pieces of a visible region (`mask`, `seen` pixels,
    bounding rectangle `rect`) that falls into two or more of at least max(4, 5 % of `seen`) pixels; none otherwise.
    Labelled within `rect` from an even row and column of the mask: OpenCV labels 2x2 blocks, so the same blocks give
    the same pieces in the same order as the whole mask does, in less area."""
    bx, by, bw, bh = rect
    cx, cy = bx - bx % 2, by - by % 2
    count, _, stats, _ = cv2.connectedComponentsWithStats(mask[cy: by + bh, cx: bx + bw], connectivity=8)
    big = stats[1:, cv2.CC_STAT_AREA] >= max(4, 0.05 * seen)
    if count <= 2 or big.sum() < 2:
        return np.zeros((0, 4), np.int32)
    return stats[1:][big][:, :4] + (cx, cy, 0, 0)


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
