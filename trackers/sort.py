"""SORT (Bewley, Ge, Ott, Ramos, Upcroft 2016): Kalman-filtered boxes and Hungarian IoU association, as the reference
code abewley/sort computes it."""

from __future__ import annotations

import numpy as np

from .assignment import corner_iou, lapjv
from .base import Param, Tracker, Tracks, detections, frame_of, register
from .camera_motion import METHODS, CameraMotion, warp_centres
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
        "min_confidence": Param(0.0, None, "detections below this confidence are dropped", (0.0, 0.95)),
        "cmc": Param("none", METHODS, "camera-motion compensation from the frame (beyond the paper; see "
                                      "camera_motion.py): the predictions moved with the image")}

    @property
    def needs_frame(self) -> bool:
        return self.params["cmc"] != "none"

    def reset(self, info=None):
        self.tracks = SortTracks(self.params["iou_threshold"])
        self.camera = CameraMotion(self.params["cmc"])

    def update(self, obs) -> Tracks:
        p, tracks = self.params, self.tracks
        dets = detections(obs)
        dets = dets[dets[:, 4] >= p["min_confidence"]]
        warp = self.camera.estimate(frame_of(obs), dets[:, :4]) if self.needs_frame else None
        tracks.advance(dets, warp)
        streak, misses = tracks.counts[:, 0], tracks.counts[:, 3]
        report = (misses < 1) & ((streak >= p["min_hits"]) | (tracks.frame <= p["min_hits"]))
        return Tracks.of(*tracks.decide(report, misses <= p["max_age"]))


class CountedTracks:
    """What a tracker's tracks keep beside their filters when a rule or a policy makes its decisions: per track an
    id, its counts (streak, hits, age, misses) and its last matched detection's confidence and IoU with the
    prediction; `decide(report, keep)` returns the reported tracks and drops those not kept. With a `capacity`, the
    tracks missed longest are dropped first beyond it. Subclasses hold the filters (`_keep_filters`, `boxes`)."""

    def __init__(self, capacity: int | None = None):
        self.capacity = capacity
        self.ids = np.zeros(0, np.int64)
        self.counts = np.zeros((0, 4), np.int64)   # streak, hits, age, misses
        self.last = np.zeros((0, 2))                # confidence, match IoU of the last matched detection
        self.next_id, self.frame = 1, 0

    def __len__(self) -> int:
        return len(self.ids)

    def _keep(self, mask: np.ndarray) -> None:
        if mask.all():
            return
        self._keep_filters(mask)
        self.ids, self.counts, self.last = self.ids[mask], self.counts[mask], self.last[mask]

    def _age(self) -> None:
        """A new frame: a streak ends with a miss; ages and misses grow."""
        self.counts[self.counts[:, 3] > 0, 0] = 0
        self.counts[:, 2:] += 1

    def _matched(self, t: np.ndarray, confidence: np.ndarray, iou: np.ndarray) -> None:
        self.counts[t, 0] += 1
        self.counts[t, 1] += 1
        self.counts[t, 3] = 0
        self.last[t, 0], self.last[t, 1] = confidence, iou

    def _born(self, confidence: np.ndarray) -> None:
        """Tracks just appended to the filters, from detections of these confidences; then the capacity."""
        n = len(confidence)
        self.ids = np.concatenate([self.ids, np.arange(self.next_id, self.next_id + n)])
        self.counts = np.concatenate([self.counts, np.zeros((n, 4), np.int64)])
        self.last = np.concatenate([self.last, np.stack([confidence, np.ones(n)], axis=1)])
        self.next_id += n
        if self.capacity is not None and len(self) > self.capacity:
            order = np.argsort(self.counts[:, 3], kind="stable")
            self._keep(np.isin(np.arange(len(self)), order[:self.capacity]))

    def decide(self, report: np.ndarray, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The reported tracks' (ids, boxes), then drop those not kept."""
        report, keep = np.asarray(report, bool), np.asarray(keep, bool)
        out = self.ids[report], self.boxes()[report]
        self._keep(keep)
        return out


class SortTracks(CountedTracks):
    """SORT's tracks without its two decisions: `advance(dets)` predicts, associates and starts tracks from a frame's
    detections as the reference does. SORT decides by min_hits and max_age; `management.Candidates` hands the
    decisions to a policy."""

    def __init__(self, iou_threshold: float = 0.3, capacity: int | None = None):
        super().__init__(capacity)
        self.iou_threshold = iou_threshold
        self.kf = KalmanBank(box_model())

    def _keep_filters(self, mask: np.ndarray) -> None:
        self.kf.keep(mask)

    def advance(self, dets: np.ndarray, warp: np.ndarray | None = None) -> None:
        """Move the tracks on one frame with its detections (x, y, w, h, confidence), as SORT does; a camera-motion
        `warp` (2x3, camera_motion.py) moves the predictions before they are matched."""
        corners = dets[:, :4].copy()
        corners[:, 2:] += corners[:, :2]
        self.frame += 1
        stop_shrinking_to_nothing(self.kf)
        self.kf.predict()
        if warp is not None:
            self.kf.x, self.kf.P = warp_centres(self.kf.x, self.kf.P, warp, "centre_area")
        self._age()
        predicted = state_to_corners(self.kf.x)
        defined = ~np.isnan(predicted).any(axis=1)
        self._keep(defined)
        predicted = predicted[defined]
        matched, new, _ = associate(corners, predicted, self.iou_threshold)
        d, t = matched[:, 0], matched[:, 1]
        self.kf.update(t, corners_to_measurement(corners[d]))
        self._matched(t, dets[d, 4], paired_iou(corners[d], predicted[t]))
        self.kf.add(corners_to_measurement(corners[new]))
        self._born(dets[new, 4])

    def boxes(self) -> np.ndarray:
        """Every candidate's box (x, y, w, h) from its filter's state."""
        box = state_to_corners(self.kf.x)
        box[:, 2:] -= box[:, :2]
        return box

    def motion(self) -> tuple[np.ndarray, np.ndarray]:
        """Per track, the area's relative change and the centre's speed in pixels, per frame."""
        x = self.kf.x
        return x[:, 6] / np.maximum(x[:, 2], 1e-6), np.hypot(x[:, 4], x[:, 5])


def paired_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU of corner boxes a[i] and b[i], row by row."""
    wh = np.clip(np.minimum(a[:, 2:], b[:, 2:]) - np.maximum(a[:, :2], b[:, :2]), 0, None)
    inter = wh[:, 0] * wh[:, 1]
    area = lambda c: (c[:, 2] - c[:, 0]) * (c[:, 3] - c[:, 1])
    return inter / (area(a) + area(b) - inter)


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


def corners_to_measurement(corners: np.ndarray) -> np.ndarray:
    """x1, y1, x2, y2 -> SORT's measurement cx, cy, s (area), r (aspect w / h)."""
    w, h = corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1]
    out = np.empty((len(corners), 4))
    out[:, 0], out[:, 1], out[:, 2], out[:, 3] = corners[:, 0] + w / 2, corners[:, 1] + h / 2, w * h, w / h
    return out


def state_to_corners(x: np.ndarray) -> np.ndarray:
    """SORT's state (cx, cy, s, r, ...) -> x1, y1, x2, y2; not a number where s * r < 0 (the reference drops those)."""
    with np.errstate(invalid="ignore"):
        w = np.sqrt(x[:, 2] * x[:, 3])
        h = x[:, 2] / w
    out = np.empty((len(x), 4))
    out[:, 0], out[:, 1], out[:, 2], out[:, 3] = x[:, 0] - w / 2, x[:, 1] - h / 2, x[:, 0] + w / 2, x[:, 1] + h / 2
    return out
