"""Track bookkeeping as arrays: ids, hit and miss counters, state, score, and the filters they own.

States follow the usual life cycle: TENTATIVE (new, not yet reported) -> CONFIRMED -> deleted (removed from
the book).
"""

from __future__ import annotations

import numpy as np

from .kalman import KalmanBank

TENTATIVE, CONFIRMED = 0, 1


class TrackBook:
    """Per-track counters aligned row by row with an optional KalmanBank."""

    _COLUMNS = {"ids": np.int64, "hits": np.int64, "streak": np.int64, "misses": np.int64, "age": np.int64,
                "state": np.int8, "score": np.float64}

    def __init__(self, kf: KalmanBank | None = None):
        self.kf = kf
        self.next_id = 1
        for name, dtype in self._COLUMNS.items():
            setattr(self, name, np.zeros(0, dtype))
        self.boxes = np.zeros((0, 4))  # last associated box (trackers without a box filter use it)

    def __len__(self) -> int:
        return len(self.ids)

    def add(self, boxes: np.ndarray, scores: np.ndarray, z: np.ndarray | None = None, state: int = TENTATIVE) -> None:
        """New tracks with fresh ids at `boxes`; their filters start at measurements `z`."""
        n = len(boxes)
        new = {"ids": np.arange(self.next_id, self.next_id + n), "hits": np.ones(n), "streak": np.ones(n),
               "misses": np.zeros(n), "age": np.zeros(n), "state": np.full(n, state), "score": scores}
        for name, dtype in self._COLUMNS.items():
            setattr(self, name, np.concatenate([getattr(self, name), np.asarray(new[name], dtype)]))
        self.boxes = np.concatenate([self.boxes, np.asarray(boxes, float).reshape(-1, 4)])
        if self.kf is not None:
            self.kf.add(z)
        self.next_id += n

    def keep(self, mask: np.ndarray) -> None:
        for name in self._COLUMNS:
            setattr(self, name, getattr(self, name)[mask])
        self.boxes = self.boxes[mask]
        if self.kf is not None:
            self.kf.keep(mask)

    def predict(self) -> None:
        """One frame passes: filters predict, ages grow, and every track counts a miss until it is matched."""
        if self.kf is not None:
            self.kf.predict()
        self.age += 1
        self.misses += 1
        self.streak[self.misses > 1] = 0

    def hit(self, rows: np.ndarray, boxes: np.ndarray, scores: np.ndarray, z: np.ndarray | None = None) -> None:
        """Tracks `rows` were matched to `boxes` this frame."""
        self.hits[rows] += 1
        self.streak[rows] += 1
        self.misses[rows] = 0
        self.boxes[rows] = boxes
        self.score[rows] = scores
        if self.kf is not None:
            self.kf.update(rows, z)
