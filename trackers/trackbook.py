"""Track bookkeeping as arrays: ids, hit and miss counters, state, score, and the filters they own.

States follow the usual life cycle: TENTATIVE (new, not yet reported) -> CONFIRMED -> deleted (removed from
the book). A tracker adds columns of its own (its extra counters) and moves tracks between books (a pool of
ended tracks that can come back) without handling each column itself.
"""

from __future__ import annotations

import numpy as np

from .kalman import KalmanBank

TENTATIVE, CONFIRMED = 0, 1


class TrackBook:
    """Per-track columns aligned row by row with an optional KalmanBank."""

    _COLUMNS = {"ids": np.int64, "hits": np.int64, "streak": np.int64, "misses": np.int64, "age": np.int64,
                "state": np.int8, "score": np.float64}

    def __init__(self, kf: KalmanBank | None = None, **extra: type):
        """`extra`: the tracker's own columns, name=dtype; new rows start them at 0."""
        self.kf = kf
        self.next_id = 1
        for name, dtype in {**self._COLUMNS, **extra}.items():
            setattr(self, name, np.zeros(0, dtype))
        self.boxes = np.zeros((0, 4))  # last associated box (trackers without a box filter use it)
        self._names = [*self._COLUMNS, *extra, "boxes"]

    def __len__(self) -> int:
        return len(self.ids)

    def _append(self, n: int, values: dict) -> None:
        """n rows at the end of every column: `values` (name: array or scalar) where given, else 0."""
        for name in self._names:
            column = getattr(self, name)
            new = np.broadcast_to(np.asarray(values.get(name, 0), column.dtype), (n,) + column.shape[1:])
            setattr(self, name, np.concatenate([column, new]))

    def add(self, boxes: np.ndarray, scores: np.ndarray, z: np.ndarray | None = None, state: int = TENTATIVE) -> None:
        """New tracks with fresh ids at `boxes`; their filters start at measurements `z`."""
        n = len(boxes)
        self._append(n, {"ids": np.arange(self.next_id, self.next_id + n), "hits": 1, "streak": 1, "state": state,
                         "score": scores, "boxes": boxes})
        if self.kf is not None:
            self.kf.add(z)
        self.next_id += n

    def keep(self, mask: np.ndarray) -> None:
        for name in self._names:
            setattr(self, name, getattr(self, name)[mask])
        if self.kf is not None:
            self.kf.keep(mask)

    def move(self, rows: np.ndarray, to: TrackBook, **values) -> None:
        """Tracks `rows` (indices or a mask) leave this book for the end of `to`, ids and filters with them;
        `values` (name=array or scalar) replace their columns there, and columns this book lacks start at 0."""
        moved = {name: getattr(self, name)[rows] for name in self._names}
        to._append(len(moved["ids"]), {**moved, **values})
        if to.kf is not None:
            to.kf.x, to.kf.P = np.concatenate([to.kf.x, self.kf.x[rows]]), np.concatenate([to.kf.P, self.kf.P[rows]])
        keep = np.ones(len(self), bool)
        keep[rows] = False
        self.keep(keep)

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
