"""The compact per-frame log of an episode, which the global passes (identity, HOTA, GOSPA, centre errors) read at
the end: dense indices for ids, arrays that grow as rows are needed, `FrameLog`, every frame's ids, centres,
nonzero similarities and CLEAR matches in a few flat logs, and `FlatSimilarities`, the log's similarities laid out
flat for the identity and HOTA passes."""

from __future__ import annotations

import numpy as np

from mtt_sim.boxes import centres


class IdIndex:
    """Dense indices for arbitrary integer ids, in order of first appearance."""

    def __init__(self):
        self.index: dict[int, int] = {}
        self._last = (np.zeros(0, np.int64), np.zeros(0, np.intp))

    def __call__(self, ids: np.ndarray) -> np.ndarray:
        if np.array_equal(ids, self._last[0]):  # most frames repeat the previous frame's ids
            return self._last[1]
        d = self.index
        dense = np.array([d.setdefault(i, len(d)) for i in ids.tolist()], np.intp)
        self._last = (ids, dense)
        return dense

    def __len__(self):
        return len(self.index)


class Grow:
    """An array of rows (1-D, or `width` columns) that grows geometrically as rows are needed; `fill` for new rows."""

    def __init__(self, fill, dtype, width: int | None = None, growth: float = 2.0):
        self.fill, self.growth = fill, growth
        self.a = np.full((16,) if width is None else (16, width), fill, dtype)

    def ensure(self, n: int) -> np.ndarray:
        if n > len(self.a):
            more = np.full((max(n, int(self.growth * len(self.a))) - len(self.a), *self.a.shape[1:]), self.fill,
                           self.a.dtype)
            self.a = np.concatenate([self.a, more])
        return self.a


class Log(Grow):
    """An append-only `Grow` (growing by a quarter, so at most a fifth of it is unused)."""

    def __init__(self, dtype, width: int | None = None):
        super().__init__(0, dtype, width, growth=1.25)
        self.n = 0

    def append(self, rows: np.ndarray):
        end = self.n + len(rows)
        self.ensure(end)[self.n: end] = rows
        self.n = end

    @property
    def data(self) -> np.ndarray:
        return self.a[: self.n]


NO_ROWS = np.zeros(0, np.intp)  # the matches of a frame that has none


class FrameLog:
    """What the global passes need of every frame, stored compactly in a few flat logs: the dense GT and tracker ids,
    their box centres (GOSPA, centre errors), the nonzero similarities (row, column, value: the only pairs identity and
    HOTA count) and the CLEAR matches, and per frame the counts n, m, nonzeros and matches (about 15 KB a frame at
    200 objects, where the similarity matrix alone is 320 KB). Frames wait in a short list and join the logs in
    batches, so a frame costs a few appends to a list."""

    BATCH = 256

    def __init__(self):
        self.gt_index, self.trk_index = IdIndex(), IdIndex()  # the episode's GT and tracker ids, densely indexed
        self._flat: FlatSimilarities | None = None
        self._waiting: list[list] = []  # per frame: g, t, gt boxes, track boxes, rows, cols, sims, match rows, match cols
        self.counts = Log(np.int64, 4)
        self.gt, self.trk = Log(np.int32), Log(np.int32)
        self.gt_xy, self.trk_xy = Log(np.float64, 2), Log(np.float64, 2)
        self.nz_row, self.nz_col, self.nz_sim = Log(np.int32), Log(np.int32), Log(np.float64)
        self.match_row, self.match_col = Log(np.int32), Log(np.int32)

    def add_frame(self, g: np.ndarray, t: np.ndarray, gt_boxes: np.ndarray, trk_boxes: np.ndarray, sim: np.ndarray):
        """A frame: its dense GT and tracker indices (`gt_index`, `trk_index`), boxes and similarities."""
        self._flat = None
        if len(self._waiting) >= self.BATCH:
            self.flush()
        rows, cols = np.nonzero(sim > 0)  # similarities are never negative; a boolean scan is twice as fast
        self._waiting.append([g, t, gt_boxes, trk_boxes, rows, cols, sim[rows, cols], NO_ROWS, NO_ROWS])

    def add_matches(self, rows: np.ndarray, cols: np.ndarray):
        """The CLEAR matches (row and column indices within the frame) of the latest frame."""
        self._waiting[-1][7:] = rows, cols

    def flush(self) -> FrameLog:
        """Move the waiting frames into the logs; returns self."""
        if self._waiting:
            g, t, gb, tb, rows, cols, sims, mr, mc = (np.concatenate(c) for c in zip(*self._waiting))
            self.counts.append([(len(f[0]), len(f[1]), len(f[4]), len(f[7])) for f in self._waiting])
            for log, values in ((self.gt, g), (self.trk, t), (self.gt_xy, centres(gb)), (self.trk_xy, centres(tb)),
                                (self.nz_row, rows), (self.nz_col, cols), (self.nz_sim, sims), (self.match_row, mr),
                                (self.match_col, mc)):
                log.append(values)
            self._waiting = []
        return self

    def __len__(self) -> int:
        return self.counts.n + len(self._waiting)

    def nbytes(self) -> int:
        """Bytes the logs hold (allocated, the unused tail included)."""
        return sum(log.a.nbytes for log in vars(self.flush()).values() if isinstance(log, Log))

    def starts(self) -> np.ndarray:
        """(frames, 4): where each frame's GT rows, tracker rows, nonzeros and matches start in their logs."""
        counts = self.flush().counts.data
        return np.cumsum(counts, axis=0) - counts

    def points(self, index: int) -> tuple[np.ndarray, np.ndarray]:
        """Frame `index`'s GT and tracker box centres."""
        if index in (-1, len(self) - 1) and self._waiting:  # the latest frame (every step's GOSPA reward)
            return centres(self._waiting[-1][2]), centres(self._waiting[-1][3])
        starts = self.starts()
        (n, m, _, _), (g0, t0, _, _) = self.counts.data[index], starts[index]
        return self.gt_xy.a[g0: g0 + n], self.trk_xy.a[t0: t0 + m]

    def split_points(self) -> tuple[list, list]:
        """Every frame's GT and tracker box centres, as two lists of arrays."""
        counts = self.flush().counts.data[:, :2]
        ends = np.cumsum(counts, axis=0)
        (g0, t0), (g1, t1) = (ends - counts).T.tolist(), ends.T.tolist()
        return [self.gt_xy.a[a:b] for a, b in zip(g0, g1)], [self.trk_xy.a[a:b] for a, b in zip(t0, t1)]

    def matches(self) -> tuple[np.ndarray, np.ndarray]:
        """Episode-wide GT and tracker row indices of every CLEAR match, frame by frame."""
        starts, counts = self.starts(), self.counts.data
        frame = np.repeat(np.arange(len(self)), counts[:, 3])
        return starts[frame, 0] + self.match_row.data, starts[frame, 1] + self.match_col.data

    def flat(self) -> FlatSimilarities:
        """The similarities of every frame so far laid out flat (made once for the passes that read them)."""
        if self._flat is None:
            self._flat = FlatSimilarities(self, len(self.gt_index), len(self.trk_index))
        return self._flat


class FlatSimilarities:
    """The nonzero similarities of every frame as flat arrays, with each one's GT id and tracker id.

    This lets the global passes (identity, HOTA) run as a handful of vectorised operations over the
    whole episode instead of a Python loop of small ones per frame; pairs of zero similarity never
    count towards either. Entries run frame by frame, row-major within a frame (as np.nonzero gives them).
    """

    def __init__(self, log: FrameLog, num_gt_ids: int, num_trk_ids: int):
        starts, counts = log.starts(), log.counts.data
        self.n, self.m, self.nnz = counts[:, 0], counts[:, 1], counts[:, 2]
        self.frame = np.repeat(np.arange(len(log)), self.nnz)  # each entry's frame
        self.local_row, self.local_col = log.nz_row.data, log.nz_col.data
        self.row = starts[self.frame, 0] + self.local_row  # index into the episode's GT rows
        self.col = starts[self.frame, 1] + self.local_col  # index into the episode's tracker rows
        self.sim = log.nz_sim.data
        gcat, tcat = log.gt.data, log.trk.data
        self.gt, self.trk = gcat[self.row], tcat[self.col]
        self.gt_count = np.bincount(gcat, minlength=num_gt_ids)
        self.trk_count = np.bincount(tcat, minlength=num_trk_ids)
        self.num_gt_dets, self.num_trk_dets = len(gcat), len(tcat)

    def crowded(self) -> np.ndarray:
        """Per frame, whether some row or column holds two nonzero entries: only these frames need an assignment
        solved."""
        twice = (np.bincount(self.row)[self.row] > 1) | (np.bincount(self.col)[self.col] > 1)
        out = np.zeros(len(self.n), bool)
        out[self.frame[twice]] = True
        return out
