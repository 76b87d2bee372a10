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

from .render import draw_blob

_EMPTY4 = np.zeros((0, 4), np.float32)


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
    x0 = np.clip(boxes[:, 0], 0, width)
    y0 = np.clip(boxes[:, 1], 0, height)
    x1 = np.clip(boxes[:, 0] + boxes[:, 2], 0, width)
    y1 = np.clip(boxes[:, 1] + boxes[:, 3], 0, height)
    return np.stack([x0, y0, x1 - x0, y1 - y0], axis=1)


def _covered(boxes: np.ndarray, depth: np.ndarray, over_boxes: np.ndarray, over_depth: np.ndarray) -> np.ndarray:
    """Which boxes intersect a box drawn after them (greater depth)."""
    a0, a1 = boxes[:, None, :2], boxes[:, None, :2] + boxes[:, None, 2:]
    b0, b1 = over_boxes[None, :, :2], over_boxes[None, :, :2] + over_boxes[None, :, 2:]
    overlap = ((a0 < b1) & (b0 < a1)).all(axis=2)
    return (overlap & (over_depth[None, :] > depth[:, None])).any(axis=1)


def measure(labels: np.ndarray, ids: np.ndarray, boxes: np.ndarray, depth: np.ndarray, is_rect: np.ndarray,
            occluder_boxes: np.ndarray, occluder_depth: np.ndarray) -> Truth:
    """Truth for targets with drawn image boxes `boxes` (slot order, label = slot + 1)."""
    h, w = labels.shape
    clipped = clip_boxes(boxes, w, h)
    inside = np.flatnonzero((clipped[:, 2] > 0) & (clipped[:, 3] > 0))
    boxes, clipped, depth = boxes[inside], clipped[inside], depth[inside]
    n = len(inside)
    visibility = np.ones(n, np.float32)
    visible = clipped.astype(np.float32)
    truncated = (clipped[:, 2] < boxes[:, 2] - 1e-9) | (clipped[:, 3] < boxes[:, 3] - 1e-9)
    over_boxes = np.concatenate([boxes, occluder_boxes])
    over_depth = np.concatenate([depth, occluder_depth])
    suspects = np.flatnonzero(truncated | _covered(boxes, depth, over_boxes, over_depth))
    pieces = []
    for r in suspects:
        x0, y0 = int(clipped[r, 0]), int(clipped[r, 1])
        x1, y1 = min(int(np.ceil(clipped[r, 0] + clipped[r, 2])) + 1, w), min(int(np.ceil(clipped[r, 1] + clipped[r, 3])) + 1, h)
        mine = cv2.compare(labels[y0:y1, x0:x1], int(inside[r] + 1), cv2.CMP_EQ)
        seen = cv2.countNonZero(mine)
        alone = np.zeros_like(mine)
        draw_blob(alone, (boxes[r, 0] - x0, boxes[r, 1] - y0, boxes[r, 2], boxes[r, 3]), bool(is_rect[inside[r]]), 255)
        full = cv2.countNonZero(alone)
        visibility[r] = min(1.0, seen / full) if full else 0.0
        if not seen:
            visible[r] = 0
            continue
        bx, by, bw, bh = cv2.boundingRect(mine)
        visible[r] = (x0 + bx, y0 + by, bw, bh)
        count, _, stats, _ = cv2.connectedComponentsWithStats(mine, connectivity=8)
        big = stats[1:, cv2.CC_STAT_AREA] >= max(4, 0.05 * seen)
        if count > 2 and big.sum() >= 2:
            s = stats[1:][big]
            pieces.append(np.column_stack([np.full(len(s), r), s[:, 0] + x0, s[:, 1] + y0, s[:, 2], s[:, 3]]))
    return Truth(ids=ids[inside].astype(np.int64), boxes=clipped.astype(np.float32), visibility=visibility,
                 visible_boxes=visible.astype(np.float32), depth=depth.astype(np.float32),
                 labels=inside + 1, pieces=np.concatenate(pieces).astype(np.float32) if pieces else np.zeros((0, 5), np.float32))


def empty() -> Truth:
    """Truth of a frame with no target."""
    z = np.zeros(0)
    return Truth(z.astype(np.int64), _EMPTY4, z.astype(np.float32), _EMPTY4, z.astype(np.float32), z.astype(int),
                 np.zeros((0, 5), np.float32))
