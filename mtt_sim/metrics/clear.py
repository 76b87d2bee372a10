"""CLEAR (MOTA, MOTP, IDSW, Frag, MT/PT/ML) with the centre errors of its matches: the one family whose matching runs
frame by frame, carrying each GT id's matches over (definitions: `mtt_sim.metrics`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mtt_sim.boxes import EPS, match
from mtt_sim.metrics.family import Field, Frame
from mtt_sim.metrics.frame_log import NO_ROWS, FrameLog, Grow


@dataclass(frozen=True)
class FrameStats:
    """CLEAR counts of one frame (what the per-step rewards are made of)."""

    tp: int
    fp: int
    fn: int
    idsw: int
    num_gt: int
    similarity_sum: float  # summed similarity of the matched pairs


class Clear:
    """The CLEAR matching of each frame as it comes, its counts, and the centre errors of its matches."""

    FIELDS = (Field("MOTA", printed=True), Field("MOTP", printed=True), Field("MODA"), Field("CLR_Re"), Field("CLR_Pr"),
              Field("TP", int, printed=True), *(Field(name, int, lower_is_better=True, printed=True)
                                                for name in ("FP", "FN", "IDSW", "Frag")),
              Field("MT", int, printed=True), Field("PT", int, printed=True),
              Field("ML", int, lower_is_better=True, printed=True),
              Field("CentreError", lower_is_better=True, printed=True), Field("CentreErrorVar", lower_is_better=True))
    PER_TARGET = (Field("Coverage"), Field("CentreError", lower_is_better=True))

    def __init__(self, log: FrameLog, threshold: float):
        self.log, self.threshold = log, threshold
        # per GT id: last-ever tracker match, previous-timestep match, frame counts
        self._last = Grow(-1, np.intp)
        self._prev = Grow(-1, np.intp)
        self._seen = Grow(0, np.int64)
        self._matched = Grow(0, np.int64)
        self._frag = Grow(0, np.int64)
        self._prev_rows = np.zeros(0, np.intp)  # GT indices whose `_prev` is set
        self.tp = self.fp = self.fn = self.idsw = 0
        self.similarity_total = 0.0
        self.stats = FrameStats(0, 0, 0, 0, 0, 0.0)  # the latest frame's counts
        self.pairs = (NO_ROWS, NO_ROWS)  # the latest frame's matches: rows of its GT, columns of its tracks

    def update(self, frame: Frame) -> None:
        """Match one frame; its counts are left in `stats`, its matches in `pairs` (and the log)."""
        self.pairs = (NO_ROWS, NO_ROWS)
        g, t = frame.g, frame.t
        n = len(self.log.gt_index)
        if n > len(self._seen.a):
            for arr in (self._last, self._prev, self._seen, self._matched, self._frag):
                arr.ensure(n)
        if not len(g):  # TrackEval skips the frame before resetting the previous-timestep matches
            self.fp += len(t)
            self.stats = FrameStats(0, len(t), 0, 0, 0, 0.0)
            return
        self._seen.a[g] += 1
        if not len(t):
            self.fn += len(g)
            self.stats = FrameStats(0, 0, len(g), 0, len(g), 0.0)
            return
        self.stats = self._match(g, t, frame.sim)

    def _match(self, g: np.ndarray, t: np.ndarray, sim: np.ndarray) -> FrameStats:
        """CLEAR matching of one frame with GT and tracks, updating the carry-over state."""
        prev, last = self._prev.a, self._last.a
        rows, cols = match(sim, self.threshold - EPS, 1000.0 * (t[None, :] == prev[g][:, None]))
        mg, mt = g[rows], t[cols]
        before = last[mg]
        idsw = int(np.count_nonzero((before >= 0) & (before != mt)))
        self._matched.a[mg] += 1
        self._frag.a[mg] += prev[mg] < 0  # newly tracked (prev is reset below for everyone else)
        last[mg] = mt
        prev[self._prev_rows] = -1
        prev[mg] = mt
        self._prev_rows = mg
        self.log.add_matches(rows, cols)
        self.pairs = (rows, cols)
        tp, s = len(mg), float(sim[rows, cols].sum())
        fn, fp = len(g) - tp, len(t) - tp
        self.tp, self.fp, self.fn, self.idsw = self.tp + tp, self.fp + fp, self.fn + fn, self.idsw + idsw
        self.similarity_total += s
        return FrameStats(tp, fp, fn, idsw, len(g), s)

    def summary(self) -> dict:
        num_gt_ids = len(self.log.gt_index)
        seen = self._seen.ensure(num_gt_ids)[:num_gt_ids]
        ratio = self._matched.a[:num_gt_ids][seen > 0] / seen[seen > 0]
        mt = int((ratio > 0.8).sum())
        pt = int((ratio >= 0.2).sum()) - mt
        frag = self._frag.a[:num_gt_ids]
        gt_total = max(1, self.tp + self.fn)
        _, errors = self._match_distances()
        return {
            "MOTA": (self.tp - self.fp - self.idsw) / gt_total,
            "MOTP": self.similarity_total / max(1, self.tp),
            "MODA": (self.tp - self.fp) / gt_total,
            "CLR_Re": self.tp / gt_total, "CLR_Pr": self.tp / max(1, self.tp + self.fp),
            "TP": self.tp, "FP": self.fp, "FN": self.fn, "IDSW": self.idsw,
            "Frag": int(np.maximum(frag[frag > 0] - 1, 0).sum()),
            "MT": mt, "PT": pt, "ML": num_gt_ids - mt - pt,
            "CentreError": float(errors.mean()) if len(errors) else 0.0,
            "CentreErrorVar": float(errors.var()) if len(errors) else 0.0,
        }

    def _match_distances(self) -> tuple[np.ndarray, np.ndarray]:
        """(dense GT index, centre distance) of every match so far."""
        log = self.log
        g, t = log.matches()
        return log.gt.data[g].astype(np.intp), np.linalg.norm(log.gt_xy.data[g] - log.trk_xy.data[t], axis=1)

    def per_target(self) -> dict[int, dict]:
        """Per GT id: Coverage (the fraction of its frames with a match) and CentreError (the mean centre distance of
        those matches, nan if none): the per-target tracking error the papers plot."""
        n = len(self.log.gt_index)
        gt, dist = self._match_distances()
        total = np.bincount(gt, dist, minlength=n)
        matched, seen = self._matched.ensure(n)[:n], self._seen.ensure(n)[:n]
        with np.errstate(invalid="ignore", divide="ignore"):
            error, coverage = total / matched, matched / np.maximum(seen, 1)
        return {int(i): {"Coverage": float(coverage[k]), "CentreError": float(error[k])}
                for i, k in self.log.gt_index.index.items()}
