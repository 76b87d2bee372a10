"""Run a tracker written for Roboflow's `supervision` in the Gym loop: `update_with_detections(sv.Detections)`
returning the detections it keeps with their `tracker_id`, as supervision's ByteTrack and the trackers built on
it do. Supervision is not a dependency: its `Detections` is used when it is installed, or any class taking
`xyxy`, `confidence` and `class_id` keywords is given instead."""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from .base import Tracker, Tracks, detections
from .external import _track_rows, to_tracks


class SupervisionTracker(Tracker):
    """Wraps `model` (or a fresh `factory()` at every reset), whose `update_with_detections(dets)` takes a
    supervision `Detections` (xyxy float32 (n, 4), confidence (n,), class_id (n,) all 0) and returns one with
    `xyxy` and `tracker_id` for each track it reports. `detections_type` is the `Detections` class to build (by
    default `supervision.Detections`)."""

    name = "supervision"
    description = "any tracker with supervision's update_with_detections(Detections), run in the Gym loop"

    def __init__(self, model: Any = None, factory: Callable[[], Any] | None = None,
                 detections_type: type | None = None):
        super().__init__()
        if model is None and factory is None:
            raise ValueError("supervision: give the tracker object (model=...) or a factory that makes one")
        self.model, self.factory, self.detections_type = model, factory, detections_type

    def reset(self, info=None):
        if self.factory is not None:
            self.model = self.factory()
        if not callable(getattr(self.model, "update_with_detections", None)):
            raise TypeError(f"supervision: {type(self.model).__name__} has no update_with_detections(detections) "
                            "method")
        if self.detections_type is None:
            try:
                from supervision import Detections
            except ImportError:
                raise ImportError("supervision: `pip install supervision`, or pass detections_type= a class taking "
                                  "xyxy, confidence and class_id") from None
            self.detections_type = Detections

    def update(self, obs) -> Tracks:
        dets = detections(obs)
        xyxy = np.c_[dets[:, :2], dets[:, :2] + dets[:, 2:4]].astype(np.float32)
        out = self.model.update_with_detections(self.detections_type(
            xyxy=xyxy, confidence=dets[:, 4].astype(np.float32), class_id=np.zeros(len(dets), int)))
        ids = getattr(out, "tracker_id", None)
        if ids is None or getattr(out, "xyxy", None) is None:
            raise ValueError("supervision: update_with_detections() must return Detections with xyxy and tracker_id, "
                             f"got {type(out).__name__}")
        return to_tracks(_track_rows(np.c_[np.asarray(out.xyxy, float).reshape(-1, 4),
                                           np.asarray(ids, float).reshape(-1)]), "xyxy")
