"""Track management as a decision: SORT's association proposes candidate tracks, and a policy decides, for each
candidate and frame, whether to report it and whether to keep it alive (Xiang, Alahi and Savarese, "Learning to Track:
Online Multi-Object Tracking by Decision Making", ICCV 2015, learn these decisions; SORT makes them by rule with
min_hits and max_age).

`Candidates` is SORT's Kalman filter and Hungarian IoU association with the two decisions taken out. A linear policy
scores each candidate's features twice (report, keep); a positive score means yes. `SORT_RULES` is SORT's own rules
(min_hits=3, max_age=1) written as such a policy, so a learner can start from SORT and be held against it.
"""

from __future__ import annotations

import numpy as np

from .assignment import corner_iou
from .kalman import KalmanBank, box_model, stop_shrinking_to_nothing
from .sort import associate, corners_to_measurement, state_to_corners

COUNT_SCALE = 10  # counts (hits, streak, age, misses) enter the features as count / 10; every feature is clipped
                  # to [-1, 1]

FEATURES = (
    "matched",        # 1 if a detection was matched (or started the candidate) this frame
    "streak",         # matches in a row since the first detection (SORT's hit streak)
    "hits",           # matches in all
    "age",            # frames since the first detection
    "misses",         # frames since the last match
    "confidence",     # the last matched detection's confidence
    "match_iou",      # IoU of the last matched detection with the prediction it matched (1 at birth)
    "height",         # box height / image height
    "aspect",         # box width / height / 4
    "growth",         # the Kalman filter's area velocity / area (per frame, clipped to [-1, 1])
    "speed",          # centre speed / box height (per frame, clipped at 1)
    "overlap",        # the largest IoU with another candidate
    "border",         # distance from the box to the nearest image border / box height (clipped at 1)
    "first_frames",   # 1 in the episode's first three frames (SORT reports at once there)
)

# SORT's rules as a linear policy over (FEATURES..., 1): report when matched with a streak of 3 (or matched in the
# first three frames); keep while misses <= 1. Scores: report 8 matched + 10 streak + 5 first_frames - 10.5 (streak
# is count / 10, so positive only when matched and streak >= 3, or matched in the first frames); keep 1.5 - 10 misses.
SORT_RULES = np.zeros((2, len(FEATURES) + 1))
SORT_RULES[0, [FEATURES.index("matched"), FEATURES.index("streak"), FEATURES.index("first_frames"), -1]] = 8, 10, 5, -10.5
SORT_RULES[1, [FEATURES.index("misses"), -1]] = -10, 1.5


class Candidates:
    """SORT's tracks without its decisions: `propose(dets)` predicts, associates and starts candidates from a frame's
    detections (x, y, w, h, confidence) as SORT does, then returns every candidate's features; `decide(report, keep)`
    returns the reported tracks and drops the candidates not kept. At most `capacity` candidates live: beyond it, those
    missed longest are dropped first."""

    def __init__(self, image_size: tuple[int, int], iou_threshold: float = 0.3, capacity: int = 64):
        self.image_size, self.iou_threshold, self.capacity = image_size, iou_threshold, capacity
        self.kf = KalmanBank(box_model())
        self.ids = np.zeros(0, np.int64)
        self.counts = np.zeros((0, 4), np.int64)   # streak, hits, age, misses
        self.last = np.zeros((0, 2))                # confidence, match IoU of the last matched detection
        self.next_id, self.frame = 1, 0

    def __len__(self) -> int:
        return len(self.ids)

    def _keep(self, mask: np.ndarray) -> None:
        self.kf.keep(mask)
        self.ids, self.counts, self.last = self.ids[mask], self.counts[mask], self.last[mask]

    def propose(self, dets: np.ndarray) -> np.ndarray:
        """Move the candidates on one frame with its detections; their features (n, len(FEATURES))."""
        corners = dets[:, :4].copy()
        corners[:, 2:] += corners[:, :2]
        self.frame += 1
        stop_shrinking_to_nothing(self.kf)
        self.kf.predict()
        self.counts[self.counts[:, 3] > 0, 0] = 0   # a streak ends with a miss
        self.counts[:, 2:] += 1                     # age, misses
        predicted = state_to_corners(self.kf.x)
        defined = ~np.isnan(predicted).any(axis=1)
        self._keep(defined)
        predicted = predicted[defined]
        matched, new = associate(corners, predicted, self.iou_threshold)
        d, t = matched[:, 0], matched[:, 1]
        self.kf.update(t, corners_to_measurement(corners[d]))
        self.counts[t, 0] += 1
        self.counts[t, 1] += 1
        self.counts[t, 3] = 0
        self.last[t, 0], self.last[t, 1] = dets[d, 4], paired_iou(corners[d], predicted[t])
        self.kf.add(corners_to_measurement(corners[new]))
        self.ids = np.concatenate([self.ids, np.arange(self.next_id, self.next_id + len(new))])
        self.counts = np.concatenate([self.counts, np.zeros((len(new), 4), np.int64)])
        self.last = np.concatenate([self.last, np.stack([dets[new, 4], np.ones(len(new))], axis=1)])
        self.next_id += len(new)
        if len(self) > self.capacity:
            order = np.argsort(self.counts[:, 3], kind="stable")
            self._keep(np.isin(np.arange(len(self)), order[:self.capacity]))
        return self.features()

    def boxes(self) -> np.ndarray:
        """Every candidate's box (x, y, w, h) from its filter's state."""
        box = state_to_corners(self.kf.x)
        box[:, 2:] -= box[:, :2]
        return box

    def features(self) -> np.ndarray:
        box = self.boxes()
        width, height = self.image_size
        h = np.maximum(box[:, 3], 1e-6)
        corners = np.c_[box[:, :2], box[:, :2] + box[:, 2:]]
        overlap = corner_iou(corners, corners) if len(box) else np.zeros((0, 0))
        np.fill_diagonal(overlap, 0.0)
        border = np.minimum.reduce([corners[:, 0], corners[:, 1], width - corners[:, 2], height - corners[:, 3]])
        counts = np.minimum(self.counts / COUNT_SCALE, 1.0)
        x = self.kf.x
        columns = [self.counts[:, 3] == 0, *counts.T, *self.last.T, box[:, 3] / height, box[:, 2] / h / 4,
                   x[:, 6] / np.maximum(x[:, 2], 1e-6), np.hypot(x[:, 4], x[:, 5]) / h,
                   overlap.max(axis=1, initial=0.0), border / h, np.full(len(box), float(self.frame <= 3))]
        return np.stack(columns, axis=1).clip(-1, 1).astype(np.float32)

    def decide(self, report: np.ndarray, keep: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The reported candidates' (ids, boxes), then drop those not kept."""
        report, keep = np.asarray(report, bool), np.asarray(keep, bool)
        out = self.ids[report], self.boxes()[report]
        self._keep(keep)
        return out


def paired_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU of corner boxes a[i] and b[i], row by row."""
    wh = np.clip(np.minimum(a[:, 2:], b[:, 2:]) - np.maximum(a[:, :2], b[:, :2]), 0, None)
    inter = wh[:, 0] * wh[:, 1]
    area = lambda c: (c[:, 2] - c[:, 0]) * (c[:, 3] - c[:, 1])
    return inter / (area(a) + area(b) - inter)


def decisions(weights: np.ndarray, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A linear policy's (report, keep) for each row of `features`: the sign of weights (2, F + 1) on (features, 1)."""
    scores = features @ weights[:, :-1].T + weights[:, -1]
    return scores[:, 0] > 0, scores[:, 1] > 0
