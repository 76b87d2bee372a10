"""Track management as a decision: a base tracker's association proposes candidate tracks, and a policy decides, for
each candidate and frame, whether to report it and whether to keep it alive (Xiang, Alahi and Savarese, "Learning to
Track: Online Multi-Object Tracking by Decision Making", ICCV 2015, learn these decisions; SORT makes them by rule with
min_hits and max_age, ByteTrack with its activation and track buffer).

`Candidates` is a base's association with the two decisions taken out (associations.py): SORT's Kalman filter and
Hungarian IoU association (`SortAssociation`), or ByteTrack's (`ByteAssociation`: its filter and its two rounds, the
second with the low-confidence detections). A linear policy scores each candidate's features twice (report, keep); a positive score
means yes. `SORT_RULES` is SORT's own rules (min_hits=3, max_age=1) written as such a policy, so a learner can start
from SORT and be held against it.
"""

from __future__ import annotations

import numpy as np

from .assignment import corner_iou, corners
from .associations import ByteAssociation, SortAssociation

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


class Candidates:
    """A base tracker's tracks as candidates for a policy: `propose(dets)` moves them on one frame by the base's
    association and returns every candidate's features; `decide(report, keep)` returns the reported tracks and drops
    those not kept. At most `capacity` candidates live: beyond it, those missed longest are dropped first."""

    def __init__(self, image_size: tuple[int, int], iou_threshold: float = 0.3, capacity: int = 64,
                 base: str = "sort"):
        if base not in BASES:
            raise ValueError(f"base={base!r}: allowed: {', '.join(map(repr, BASES))} (the tracker whose association "
                             "proposes the candidates)")
        self.tracks = SortAssociation(iou_threshold, capacity) if base == "sort" else ByteAssociation(capacity=capacity)
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
        counts = np.minimum(np.stack([t.streak, t.hits, t.age, t.misses], axis=1) / COUNT_SCALE, 1.0)
        growth, speed = t.motion()
        columns = [t.misses == 0, *counts.T, t.confidence, t.match_iou, box[:, 3] / height, box[:, 2] / h / 4, growth,
                   speed / h, overlap.max(axis=1, initial=0.0), border / h, np.full(len(box), float(t.frame <= 3))]
        return np.stack(columns, axis=1).clip(-1, 1).astype(np.float32)


def decisions(weights: np.ndarray, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A linear policy's (report, keep) for each row of `features`: the sign of weights (2, F + 1) on (features, 1)."""
    scores = features @ weights[:, :-1].T + weights[:, -1]
    return scores[:, 0] > 0, scores[:, 1] > 0
