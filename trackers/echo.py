"""The floor: every detection becomes a track for one frame."""

from __future__ import annotations

import numpy as np

from .base import Param, Tracker, Tracks, detections


class Echo(Tracker):
    """Reports each frame's detections (at or above min_confidence) as tracks numbered 1..n afresh every frame:
    no filtering, no identity. What a tracker must beat."""

    name = "echo"
    description = "Floor baseline: each frame's detections as tracks, numbered afresh every frame"
    parameters = {
        "min_confidence": Param(0.0, None, "detections below this confidence are dropped")}

    def update(self, obs) -> Tracks:
        dets = detections(obs)
        dets = dets[dets[:, 4] >= self.params["min_confidence"]]
        return Tracks.of(np.arange(1, len(dets) + 1), dets[:, :4], dets[:, 4])
