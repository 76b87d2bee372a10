"""A tracker's association without its decisions: SORT's and ByteTrack's tracks, moved on one frame at a time by
`advance(dets)`, in a track table that also keeps each track's last matched detection (its confidence and its IoU with
the prediction it matched). What to report and what to keep is decided outside, by a rule (SORT's min_hits and
max_age) or by a policy (management.py), through `decide(report, keep)`."""

from __future__ import annotations

import numpy as np

from .assignment import corners, lapjv, paired_iou, plus_one_iou
from .boxes import corners_to_measurement, state_to_corners, tlwh_to_xyah, xyah_to_corners, xyah_to_tlwh
from .camera_motion import warp_centres
from .kalman import KalmanBank, box_model, stop_shrinking_to_nothing, xyah_initiate, xyah_predict, xyah_update
from .rounds import associate
from .track_table import TrackTable


class Association(TrackTable):
    """The tracks of an association that leaves its decisions to `decide`. With a `capacity`, the tracks missed
    longest are dropped first beyond it. Subclasses move the tracks (`advance`) and read their boxes (`boxes`)."""

    def __init__(self, capacity: int | None = None, kf: KalmanBank | None = None, **columns):
        super().__init__(kf, confidence=np.float64, match_iou=np.float64, **columns)
        self.capacity = capacity

    def _matched(self, rows: np.ndarray, confidence: np.ndarray, iou: np.ndarray) -> None:
        self.matched(rows)
        self.confidence[rows], self.match_iou[rows] = confidence, iou

    def _born(self, confidence: np.ndarray, z: np.ndarray | None = None, **values) -> None:
        """New tracks from detections of these confidences (IoU 1 with themselves); then the capacity."""
        self.add(len(confidence), z, confidence=confidence, match_iou=1.0, **values)
        if self.capacity is not None and len(self) > self.capacity:
            order = np.argsort(self.misses, kind="stable")
            self.keep(np.isin(np.arange(len(self)), order[:self.capacity]))

    def decide(self, report: np.ndarray, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The reported tracks' (ids, boxes), then drop those not kept."""
        report, keep = np.asarray(report, bool), np.asarray(keep, bool)
        out = self.ids[report], self.boxes()[report]
        self.keep(keep)
        return out


class SortAssociation(Association):
    """SORT's tracks: `advance(dets)` predicts, associates and starts tracks from a frame's detections as the
    reference does (`Sort` then decides by min_hits and max_age)."""

    def __init__(self, iou_threshold: float = 0.3, capacity: int | None = None):
        super().__init__(capacity, KalmanBank(box_model()))
        self.iou_threshold = iou_threshold

    def advance(self, dets: np.ndarray, warp: np.ndarray | None = None) -> None:
        """Move the tracks on one frame with its detections (x, y, w, h, confidence), as SORT does; a camera-motion
        `warp` (2x3, camera_motion.py) moves the predictions before they are matched."""
        xyxy = dets[:, :4].copy()
        xyxy[:, 2:] += xyxy[:, :2]
        stop_shrinking_to_nothing(self.kf)
        self.kf.predict()
        if warp is not None:
            self.kf.x, self.kf.P = warp_centres(self.kf.x, self.kf.P, warp, "centre_area")
        self.tick()
        predicted = state_to_corners(self.kf.x)
        defined = ~np.isnan(predicted).any(axis=1)
        self.keep(defined)
        predicted = predicted[defined]
        matched, new, _ = associate(xyxy, predicted, self.iou_threshold)
        d, t = matched[:, 0], matched[:, 1]
        self.kf.update(t, corners_to_measurement(xyxy[d]))
        self._matched(t, dets[d, 4], paired_iou(xyxy[d], predicted[t]))
        self._born(dets[new, 4], corners_to_measurement(xyxy[new]))

    def boxes(self) -> np.ndarray:
        """Every track's box (x, y, w, h) from its filter's state."""
        box = state_to_corners(self.kf.x)
        box[:, 2:] -= box[:, :2]
        return box

    def motion(self) -> tuple[np.ndarray, np.ndarray]:
        """Per track, the area's relative change and the centre's speed in pixels, per frame."""
        x = self.kf.x
        return x[:, 6] / np.maximum(x[:, 2], 1e-6), np.hypot(x[:, 4], x[:, 5])


class ByteAssociation(Association):
    """ByteTrack's association (its two rounds) without its decisions: every frame the tracks predict with
    ByteTrack's filter (height velocity held where a track was missed), take the detections over track_thresh (cost
    1 - IoU x confidence, at most match_thresh); those matched last frame and not now take the detections between
    0.1 and track_thresh (1 - IoU, at most 0.5); detections over track_thresh + 0.1 left start tracks. What the
    `ByteTrack` tracker decides by rule (activation on a second match, removal of a new track missed once, the track
    buffer) is left to `decide`. IoU counts pixels inclusively, as ByteTrack's."""

    def __init__(self, track_thresh: float = 0.5, match_thresh: float = 0.8, capacity: int | None = None):
        super().__init__(capacity, mean=(np.float64, (8,)), cov=(np.float64, (8, 8)))
        self.track_thresh, self.match_thresh = track_thresh, match_thresh

    def advance(self, dets: np.ndarray) -> None:
        """Move the tracks on one frame with its detections (x, y, w, h, confidence)."""
        score = dets[:, 4]
        high = np.flatnonzero(score > self.track_thresh)
        low = np.flatnonzero((score > 0.1) & (score < self.track_thresh))
        was_tracked = self.misses == 0
        mean = self.mean.copy()
        mean[~was_tracked, 7] = 0.0
        self.mean, self.cov = xyah_predict(mean, self.cov)
        self.tick()
        predicted = xyah_to_corners(self.mean)
        boxes = corners(dets[:, :4])
        iou = plus_one_iou(predicted, boxes)
        first = lapjv(1 - iou[:, high] * score[high], self.match_thresh)
        t1, d1 = first[0][:, 0], high[first[0][:, 1]]
        rest = first[1][was_tracked[first[1]]]
        second = lapjv(1 - iou[np.ix_(rest, low)], 0.5)
        t2, d2 = rest[second[0][:, 0]], low[second[0][:, 1]]
        t, d = np.concatenate([t1, t2]), np.concatenate([d1, d2])
        self.mean[t], self.cov[t] = xyah_update(self.mean[t], self.cov[t], tlwh_to_xyah(dets[d, :4]))
        self._matched(t, score[d], paired_iou(predicted[t], boxes[d]))
        born = high[first[2]]
        born = born[score[born] >= self.track_thresh + 0.1]
        mean, cov = xyah_initiate(tlwh_to_xyah(dets[born, :4]))
        self._born(score[born], mean=mean, cov=cov)

    def boxes(self) -> np.ndarray:
        """Every track's box (x, y, w, h) from its filter's mean (cx, cy, aspect, height)."""
        return xyah_to_tlwh(self.mean)

    def motion(self) -> tuple[np.ndarray, np.ndarray]:
        """Per track, the area's relative change and the centre's speed in pixels, per frame."""
        m = self.mean
        return m[:, 6] / np.maximum(m[:, 2], 1e-6) + 2 * m[:, 7] / np.maximum(m[:, 3], 1e-6), np.hypot(m[:, 4], m[:, 5])
