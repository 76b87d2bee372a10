"""Run a third-party tracker inside the Gym loop: any object with `update(detections) -> tracks` on arrays."""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from .base import Tracker, Tracks, detections, frame_of

FORMATS = ("xywh", "xyxy")


class External(Tracker):
    """Wraps `model`, whose `update(dets)` takes an (n, 5) array of boxes and confidences and returns an (m, >= 5)
    array of boxes and track ids: x, y, w, h, id with box_format="xywh", or x1, y1, x2, y2, id with "xyxy" (the
    convention of the SORT reference code and many trackers built on it). Columns after the fifth are ignored.
    With pass_frame=True the model is called as update(dets, frame) with the RGB frame. `factory`, if given, makes
    a fresh model at every reset (otherwise the same model carries on across episodes)."""

    name = "external"
    description = "any object with update(detections) -> tracks, run in the Gym loop"

    def __init__(self, model: Any = None, box_format: str = "xyxy", pass_frame: bool = False,
                 factory: Callable[[], Any] | None = None):
        super().__init__()
        if box_format not in FORMATS:
            raise ValueError(f"external: box_format={box_format!r}: allowed values: 'xywh', 'xyxy'")
        if model is None and factory is None:
            raise ValueError("external: give the tracker object (model=...) or a factory that makes one")
        self.model, self.factory, self.box_format, self.needs_frame = model, factory, box_format, pass_frame

    def reset(self, info=None):
        if self.factory is not None:
            self.model = self.factory()
        if not callable(getattr(self.model, "update", None)):
            raise TypeError(f"external: {type(self.model).__name__} has no update(detections) method")

    def update(self, obs) -> Tracks:
        dets = detections(obs).copy()
        if self.box_format == "xyxy":
            dets[:, 2:4] += dets[:, :2]
        args = (dets, frame_of(obs)) if self.needs_frame else (dets,)
        return to_tracks(_track_rows(self.model.update(*args)), self.box_format)


def to_tracks(rows: np.ndarray, box_format: str) -> Tracks:
    """Checked (m, >= 5) rows of boxes (x, y, w, h or x1, y1, x2, y2) and ids as Tracks, each with score 1."""
    boxes = rows[:, :4].copy()
    if box_format == "xyxy":
        boxes[:, 2:] -= boxes[:, :2]
    return Tracks.of(rows[:, 4].astype(np.int64), boxes, np.ones(len(rows)))


def _track_rows(out) -> np.ndarray:
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
