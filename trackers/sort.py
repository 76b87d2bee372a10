"""SORT (Bewley, Ge, Ott, Ramos, Upcroft 2016): Kalman-filtered boxes and Hungarian IoU association, as the reference
code abewley/sort computes it."""

from __future__ import annotations

import numpy as np

from .assignment import corner_iou, lapjv
from .base import Param, Tracker, Tracks, detections, register
from .kalman import KalmanBank, box_model, stop_shrinking_to_nothing


@register
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
        "min_confidence": Param(0.0, None, "detections below this confidence are dropped", (0.0, 0.95))}

    def reset(self, info=None):
        self.kf = KalmanBank(box_model())
        self.ids = np.zeros(0, np.int64)
        self.streak = np.zeros(0, np.int64)      # matches in a row since the track's first detection
        self.since_update = np.zeros(0, np.int64)  # frames since the last match
        self.next_id, self.frame = 1, 0

    def _keep(self, mask: np.ndarray) -> None:
        self.kf.keep(mask)
        self.ids, self.streak, self.since_update = self.ids[mask], self.streak[mask], self.since_update[mask]

    def update(self, obs) -> Tracks:
        p = self.params
        dets = detections(obs)
        corners = dets[dets[:, 4] >= p["min_confidence"], :4].copy()
        corners[:, 2:] += corners[:, :2]
        self.frame += 1
        stop_shrinking_to_nothing(self.kf)
        self.kf.predict()
        self.streak[self.since_update > 0] = 0
        self.since_update += 1
        predicted = state_to_corners(self.kf.x)
        defined = ~np.isnan(predicted).any(axis=1)
        self._keep(defined)
        matched, new = associate(corners, predicted[defined], p["iou_threshold"])
        self.kf.update(matched[:, 1], corners_to_measurement(corners[matched[:, 0]]))
        self.streak[matched[:, 1]] += 1
        self.since_update[matched[:, 1]] = 0
        self.kf.add(corners_to_measurement(corners[new]))
        self.ids = np.r_[self.ids, np.arange(self.next_id, self.next_id + len(new))]
        self.streak, self.since_update = np.r_[self.streak, np.zeros(len(new), np.int64)], np.r_[
            self.since_update, np.zeros(len(new), np.int64)]
        self.next_id += len(new)
        report = (self.since_update < 1) & ((self.streak >= p["min_hits"]) | (self.frame <= p["min_hits"]))
        box = state_to_corners(self.kf.x[report])
        box[:, 2:] -= box[:, :2]
        out = Tracks.of(self.ids[report], box)
        self._keep(self.since_update <= p["max_age"])
        return out


def associate(dets: np.ndarray, tracks: np.ndarray, threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """The reference's association of detection and track corners: (matches (k, 2) of detection and track rows,
    unmatched detections in the order the reference starts tracks from them)."""
    if not len(tracks):
        return np.zeros((0, 2), np.intp), np.arange(len(dets))
    iou = corner_iou(dets, tracks)
    if min(iou.shape) > 0:
        above = iou > threshold
        if above.sum(1).max() == 1 and above.sum(0).max() == 1:  # each pair above the threshold is alone
            matched = np.stack(np.nonzero(above), axis=1)
        else:
            matched = lapjv(-iou)[0]
    else:
        matched = np.zeros((0, 2), np.intp)
    low = iou[matched[:, 0], matched[:, 1]] < threshold
    unmatched = np.setdiff1d(np.arange(len(dets)), matched[:, 0])  # never paired, then paired but under threshold
    return matched[~low], np.r_[unmatched, matched[low, 0]].astype(np.intp)


def corners_to_measurement(corners: np.ndarray) -> np.ndarray:
    """x1, y1, x2, y2 -> SORT's measurement cx, cy, s (area), r (aspect w / h)."""
    w, h = corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1]
    return np.stack([corners[:, 0] + w / 2, corners[:, 1] + h / 2, w * h, w / h], axis=1)


def state_to_corners(x: np.ndarray) -> np.ndarray:
    """SORT's state (cx, cy, s, r, ...) -> x1, y1, x2, y2; not a number where s * r < 0 (the reference drops those)."""
    with np.errstate(invalid="ignore"):
        w = np.sqrt(x[:, 2] * x[:, 3])
        h = x[:, 2] / w
    return np.stack([x[:, 0] - w / 2, x[:, 1] - h / 2, x[:, 0] + w / 2, x[:, 1] + h / 2], axis=1)
