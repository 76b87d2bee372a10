"""IoU association rounds as the reference trackers run them: SORT's round (`associate`, with OC-SORT's direction
bonus) and a second round by IoU alone (`rematch`: OC-SORT's recovery, BYTE's low-confidence round)."""

from __future__ import annotations

import numpy as np

from .assignment import corner_iou, lapjv


def associate(dets: np.ndarray, tracks: np.ndarray, threshold: float,
              bonus: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The reference's association of detection and track corners: (matches (k, 2) of detection and track rows,
    unmatched detections in the order the reference starts tracks from them, unmatched tracks likewise). Where the
    pairs above the threshold are not all alone, the assignment maximises IoU plus `bonus` (OC-SORT's direction term;
    none for SORT); a pair under the threshold is undone either way."""
    if not len(tracks):
        return np.zeros((0, 2), np.intp), np.arange(len(dets)), np.zeros(0, np.intp)
    iou = corner_iou(dets, tracks)
    if min(iou.shape) > 0:
        above = iou > threshold
        if above.sum(1).max() == 1 and above.sum(0).max() == 1:  # each pair above the threshold is alone
            matched = np.argwhere(above)
        else:
            matched = lapjv(-iou if bonus is None else -(iou + bonus))[0]
    else:
        matched = np.zeros((0, 2), np.intp)
    low = iou[matched[:, 0], matched[:, 1]] < threshold
    # never paired, then paired but under the threshold
    left_dets = np.concatenate([without(len(dets), matched[:, 0]), matched[low, 0]])
    left_tracks = np.concatenate([without(len(tracks), matched[:, 1]), matched[low, 1]])
    return matched[~low], left_dets.astype(np.intp), left_tracks.astype(np.intp)


def without(n: int, rows: np.ndarray) -> np.ndarray:
    """0..n-1 in order, less `rows` (np.setdiff1d(np.arange(n), rows), without its sorting)."""
    keep = np.ones(n, bool)
    keep[rows] = False
    return np.flatnonzero(keep)


def rematch(dets: np.ndarray, boxes: np.ndarray, threshold: float) -> tuple[np.ndarray, np.ndarray] | None:
    """A second-round matching by IoU alone (OCR, BYTE): (detection rows, box rows) of the assignment's pairs at or
    over the threshold; None where no IoU exceeds it (the reference then leaves its lists as they are)."""
    iou = corner_iou(dets[:, :4], boxes[:, :4])
    if iou.max() <= threshold:
        return None
    pairs = lapjv(-iou)[0]
    pairs = pairs[iou[pairs[:, 0], pairs[:, 1]] >= threshold]
    return pairs[:, 0], pairs[:, 1]
