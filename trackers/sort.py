"""SORT (Bewley, Ge, Ott, Ramos, Upcroft 2016): Kalman-filtered boxes and Hungarian IoU association, as the reference
code abewley/sort computes it."""

from __future__ import annotations

from .base import Param, Tracker, Tracks, detections, frame_of
from .parts.associations import SortAssociation
from .parts.camera_motion import METHODS, CameraMotion


class Sort(Tracker):
    """Each track is a constant-velocity Kalman filter on (cx, cy, area, aspect) with the reference code's noise.
    Every frame all tracks predict (a track whose predicted box is not a number is dropped), detections and predicted
    boxes are matched by the Hungarian algorithm on IoU and pairs under iou_threshold are then undone, matched tracks
    are corrected, and unmatched detections start tracks, in the reference's order (so ids agree). A track is
    reported in frames where it was matched once min_hits matches in a row have followed its first detection (or
    during the first min_hits frames), and deleted after max_age frames without a match. Box for box the reference
    `sort.py` (commit 2236dff) on the same detections; detections under min_confidence (0: none) are ignored first."""

    name = "sort"
    description = "SORT (Bewley et al. 2016): Kalman boxes + Hungarian IoU matching, min_hits, max_age"
    parameters = {
        "max_age": Param(1, "[0, inf)", "frames a track is kept without a match", (1, 30)),
        "min_hits": Param(3, "[0, inf)", "matches in a row before a track is reported (from the first frames at "
                                         "once, as the reference)", (0, 6)),
        "iou_threshold": Param(0.3, "[0, 1]", "least IoU of a match", (0.05, 0.7)),
        "min_confidence": Param(0.0, None, "detections below this confidence are dropped", (0.0, 0.95)),
        "cmc": Param("none", METHODS, "camera-motion compensation from the frame (beyond the paper; see "
                                      "parts/camera_motion.py): the predictions moved with the image")}

    @property
    def needs_frame(self) -> bool:
        return self.params["cmc"] != "none"

    def reset(self, info=None):
        self.tracks = SortAssociation(self.params["iou_threshold"])
        self.camera = CameraMotion(self.params["cmc"])

    def update(self, obs) -> Tracks:
        p, tracks = self.params, self.tracks
        dets = detections(obs)
        dets = dets[dets[:, 4] >= p["min_confidence"]]
        warp = self.camera.estimate(frame_of(obs), dets[:, :4]) if self.needs_frame else None
        tracks.advance(dets, warp)
        report = (tracks.misses < 1) & ((tracks.streak >= p["min_hits"]) | (tracks.frame <= p["min_hits"]))
        return Tracks.of(*tracks.decide(report, tracks.misses <= p["max_age"]))
