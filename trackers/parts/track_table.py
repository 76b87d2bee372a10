"""The track table: every tracker that keeps counted tracks keeps them here, as arrays, one row per track.

Each row has an id and four named counters, as abewley's `sort.py` names them on its tracks:

- `hits`: matches in all; `streak`: matches in a row (a frame without a match ends it);
- `age`: frames since the track was born; `misses`: frames since its last match (0 in a frame it was matched).

A tracker declares its own columns beside them (its filter's state, a life-cycle `state`, its last box...), and the
table adds, keeps and moves rows with every column at once, its Kalman bank's rows too. The birth values are the
tracker's (SORT's reference starts a track at 0 hits, gnn at 1: its birth is its first detection).
"""

from __future__ import annotations

import numpy as np

from .kalman import KalmanBank

TENTATIVE, CONFIRMED = 0, 1  # a life cycle trackers may keep in a `state` column: new, then reported
COUNTERS = ("hits", "streak", "age", "misses")


class TrackTable:
    """Per-track columns aligned row by row (with an optional KalmanBank): ids, COUNTERS and the tracker's own."""

    def __init__(self, kf: KalmanBank | None = None, **columns):
        """`columns`: the tracker's own, name=dtype (one value per track) or name=(dtype, shape); new rows start
        them at 0 unless `add` is given a value."""
        self.kf = kf
        self.next_id, self.frame = 1, 0
        self._names = []
        for name, kind in {"ids": np.int64, **dict.fromkeys(COUNTERS, np.int64), **columns}.items():
            dtype, shape = kind if isinstance(kind, tuple) else (kind, ())
            setattr(self, name, np.zeros((0, *shape), dtype))
            self._names.append(name)

    def __len__(self) -> int:
        return len(self.ids)

    def _append(self, n: int, values: dict) -> None:
        """n rows at the end of every column: `values` (name: array or scalar) where given, else 0."""
        for name in self._names:
            column = getattr(self, name)
            new = np.broadcast_to(np.asarray(values.get(name, 0), column.dtype), (n,) + column.shape[1:])
            setattr(self, name, np.concatenate([column, new]))

    def add(self, n: int, z: np.ndarray | None = None, **values) -> None:
        """n new tracks with fresh ids at the end; `values` (name=array or scalar) start their columns (else 0),
        and the filters start at measurements `z`."""
        self._append(n, {**values, "ids": np.arange(self.next_id, self.next_id + n)})
        if self.kf is not None:
            self.kf.add(z)
        self.next_id += n

    def keep(self, mask: np.ndarray) -> None:
        """Keep the rows where the boolean `mask` holds, in order."""
        if mask.all():
            return
        for name in self._names:
            setattr(self, name, getattr(self, name)[mask])
        if self.kf is not None:
            self.kf.keep(mask)

    def move(self, rows: np.ndarray, to: TrackTable, **values) -> None:
        """Tracks `rows` (indices or a mask) leave this table for the end of `to`, ids and filters with them;
        `values` (name=array or scalar) replace their columns there, and columns this table lacks start at 0."""
        moved = {name: getattr(self, name)[rows] for name in self._names}
        to._append(len(moved["ids"]), {**moved, **values})
        if to.kf is not None:
            to.kf.x, to.kf.P = np.concatenate([to.kf.x, self.kf.x[rows]]), np.concatenate([to.kf.P, self.kf.P[rows]])
        keep = np.ones(len(self), bool)
        keep[rows] = False
        self.keep(keep)

    def tick(self) -> None:
        """A new frame: a streak ends with a miss; every track ages and counts a miss until it is matched."""
        self.frame += 1
        self.streak[self.misses > 0] = 0
        self.age += 1
        self.misses += 1

    def matched(self, rows: np.ndarray) -> None:
        """Tracks `rows` were matched this frame."""
        self.hits[rows] += 1
        self.streak[rows] += 1
        self.misses[rows] = 0
