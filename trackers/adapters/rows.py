"""An outside tracker's output rows (boxes and ids), checked and read as Tracks: what the adapters share."""

from __future__ import annotations

import numpy as np

from ..base import Tracks


def to_tracks(rows: np.ndarray, box_format: str) -> Tracks:
    """Checked (m, >= 5) rows of boxes (x, y, w, h or x1, y1, x2, y2) and ids as Tracks, each with score 1."""
    boxes = rows[:, :4].copy()
    if box_format == "xyxy":
        boxes[:, 2:] -= boxes[:, :2]
    return Tracks.of(rows[:, 4].astype(np.int64), boxes, np.ones(len(rows)))


def track_rows(out) -> np.ndarray:
    """A model's update() result as a checked (m, >= 5) float array: finite boxes, ids unique non-negative integers."""
    what = "external: update() must return an (m, >= 5) array of boxes and track ids"
    try:
        rows = np.asarray(out, float)
    except (TypeError, ValueError):
        raise ValueError(f"{what}, got {type(out).__name__}") from None
    if rows.size == 0:
        return np.zeros((0, 5))
    rows = rows.reshape(1, -1) if rows.ndim == 1 else rows
    if rows.ndim != 2 or rows.shape[1] < 5:
        raise ValueError(f"{what}, got {type(out).__name__} of shape {rows.shape}")
    bad = ~np.isfinite(rows[:, :5]).all(axis=1)
    if bad.any():
        raise ValueError(f"{what}: row {int(np.flatnonzero(bad)[0])} is not finite: {rows[bad][0, :5].tolist()}")
    ids = rows[:, 4]
    wrong = (ids != np.round(ids)) | (ids < 0) | (ids > 2**31 - 1)
    if wrong.any():
        raise ValueError(f"{what}: track ids must be integers in 0..2**31-1, row {int(np.flatnonzero(wrong)[0])} has "
                         f"{float(ids[wrong][0]):g}")
    uniq, counts = np.unique(ids, return_counts=True)
    if (counts > 1).any():
        raise ValueError(f"{what}: track ids must be unique within a frame; repeated: {uniq[counts > 1].astype(int).tolist()}")
    return rows
