"""Track management as a decision: a base tracker's association proposes candidate tracks, and a policy decides, for
each candidate and frame, whether to report it and whether to keep it alive (Xiang, Alahi and Savarese, "Learning to
Track: Online Multi-Object Tracking by Decision Making", ICCV 2015, learn these decisions; SORT makes them by rule with
min_hits and max_age, ByteTrack with its activation and track buffer).

`Candidates` is a base's association with the two decisions taken out: SORT's Kalman filter and Hungarian IoU
association (`sort.SortTracks`), or ByteTrack's (`ByteTracks`: its filter and its two rounds, the second with the
low-confidence detections). A linear policy scores each candidate's features twice (report, keep); a positive score
means yes. `SORT_RULES` is SORT's own rules (min_hits=3, max_age=1) written as such a policy, so a learner can start
from SORT and be held against it.
"""

from __future__ import annotations

import numpy as np

from .assignment import corner_iou, corners, lapjv, plus_one_iou
from .bytetrack import tlwh_to_xyah, xyah_to_corners, xyah_to_tlwh
from .kalman import xyah_initiate, xyah_predict, xyah_update
from .sort import CountedTracks, SortTracks, paired_iou

BASES = ("sort", "bytetrack")

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


class ByteTracks(CountedTracks):
    """ByteTrack's association without its decisions, with SortTracks' interface: every frame the tracks predict with
    ByteTrack's filter (height velocity held where a track was missed), take the detections over track_thresh (cost
    1 - IoU x confidence, at most match_thresh); those matched last frame and not now take the detections between
    0.1 and track_thresh (1 - IoU, at most 0.5); detections over track_thresh + 0.1 left start tracks. What ByteTrack
    decides by rule (activation on a second match, removal of a new track missed once, the track buffer) is left to
    `decide`. IoU counts pixels inclusively, as ByteTrack's."""

    def __init__(self, track_thresh: float = 0.5, match_thresh: float = 0.8, capacity: int | None = None):
        super().__init__(capacity)
        self.track_thresh, self.match_thresh = track_thresh, match_thresh
        self.mean, self.cov = np.zeros((0, 8)), np.zeros((0, 8, 8))

    def _keep_filters(self, mask: np.ndarray) -> None:
        self.mean, self.cov = self.mean[mask], self.cov[mask]

    def advance(self, dets: np.ndarray) -> None:
        """Move the tracks on one frame with its detections (x, y, w, h, confidence)."""
        self.frame += 1
        score = dets[:, 4]
        high = np.flatnonzero(score > self.track_thresh)
        low = np.flatnonzero((score > 0.1) & (score < self.track_thresh))
        was_tracked = self.counts[:, 3] == 0
        mean = self.mean.copy()
        mean[~was_tracked, 7] = 0.0
        self.mean, self.cov = xyah_predict(mean, self.cov)
        self._age()
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
        self.mean, self.cov = np.concatenate([self.mean, mean]), np.concatenate([self.cov, cov])
        self._born(score[born])

    def boxes(self) -> np.ndarray:
        """Every track's box (x, y, w, h) from its filter's mean (cx, cy, aspect, height)."""
        return xyah_to_tlwh(self.mean)

    def motion(self) -> tuple[np.ndarray, np.ndarray]:
        """Per track, the area's relative change and the centre's speed in pixels, per frame."""
        m = self.mean
        return m[:, 6] / np.maximum(m[:, 2], 1e-6) + 2 * m[:, 7] / np.maximum(m[:, 3], 1e-6), np.hypot(m[:, 4], m[:, 5])


class Candidates:
    """A base tracker's tracks as candidates for a policy: `propose(dets)` moves them on one frame by the base's
    association and returns every candidate's features; `decide(report, keep)` returns the reported tracks and drops
    those not kept. At most `capacity` candidates live: beyond it, those missed longest are dropped first."""

    def __init__(self, image_size: tuple[int, int], iou_threshold: float = 0.3, capacity: int = 64,
                 base: str = "sort"):
        if base not in BASES:
            raise ValueError(f"base={base!r}: allowed: {', '.join(map(repr, BASES))} (the tracker whose association "
                             "proposes the candidates)")
        self.tracks = SortTracks(iou_threshold, capacity) if base == "sort" else ByteTracks(capacity=capacity)
        self.image_size = image_size

    def propose(self, dets: np.ndarray) -> np.ndarray:
        """Move the candidates on one frame with its detections; their features (n, len(FEATURES))."""
        self.tracks.advance(dets)
        return self.features()

    def __len__(self) -> int:
        return len(self.tracks)

    def boxes(self) -> np.ndarray:
        return self.tracks.boxes()

    def decide(self, report, keep) -> tuple[np.ndarray, np.ndarray]:
        return self.tracks.decide(report, keep)

    def features(self) -> np.ndarray:
        t = self.tracks
        box = t.boxes()
        width, height = self.image_size
        h = np.maximum(box[:, 3], 1e-6)
        xyxy = corners(box)
        overlap = corner_iou(xyxy, xyxy) if len(box) else np.zeros((0, 0))
        np.fill_diagonal(overlap, 0.0)
        border = np.minimum.reduce([xyxy[:, 0], xyxy[:, 1], width - xyxy[:, 2], height - xyxy[:, 3]])
        counts = np.minimum(t.counts / COUNT_SCALE, 1.0)
        growth, speed = t.motion()
        columns = [t.counts[:, 3] == 0, *counts.T, *t.last.T, box[:, 3] / height, box[:, 2] / h / 4, growth,
                   speed / h, overlap.max(axis=1, initial=0.0), border / h, np.full(len(box), float(t.frame <= 3))]
        return np.stack(columns, axis=1).clip(-1, 1).astype(np.float32)


def decisions(weights: np.ndarray, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A linear policy's (report, keep) for each row of `features`: the sign of weights (2, F + 1) on (features, 1)."""
    scores = features @ weights[:, :-1].T + weights[:, -1]
    return scores[:, 0] > 0, scores[:, 1] > 0
