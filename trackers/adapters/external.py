"""Run a third-party tracker inside the Gym loop: any object with `update(detections) -> tracks` on arrays."""

from __future__ import annotations

from typing import Any, Callable

from ..base import Tracker, Tracks, detections, frame_of
from .rows import to_tracks, track_rows

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
        return to_tracks(track_rows(self.model.update(*args)), self.box_format)
