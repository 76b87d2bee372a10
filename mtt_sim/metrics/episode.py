"""`EpisodeMetrics`: the per-frame CLEAR work as each frame arrives, and every metric of the episode on demand;
`evaluate` on a whole sequence (definitions: `mtt_sim.metrics`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from mtt_sim.boxes import EPS, box_iou, centre_distance, check_frame, match
from mtt_sim.metrics.frame_log import NO_ROWS, FrameLog, Grow, IdIndex
from mtt_sim.metrics.gospa import gospa_of_points
from mtt_sim.metrics.hota import FlatSimilarities, hota, identity
from mtt_sim.metrics.occlusion import OcclusionWindows, check_everyone

SIMILARITIES = ("iou", "centroid")


@dataclass(frozen=True)
class FrameStats:
    """CLEAR counts of one frame (what the per-step rewards are made of)."""

    tp: int
    fp: int
    fn: int
    idsw: int
    num_gt: int
    similarity_sum: float  # summed similarity of the matched pairs


class EpisodeMetrics:
    """Incremental MOT metrics for one sequence: `update` every frame, `summary` at the end."""

    def __init__(self, similarity: str = "iou", threshold: float = 0.5, zero_distance: float = 2.0,
                 gospa_c: float = 50.0, gospa_p: float = 1.0):
        if similarity not in SIMILARITIES:
            raise ValueError(f"similarity={similarity!r}: allowed values: {', '.join(map(repr, SIMILARITIES))}")
        if not 0 < threshold <= 1:
            raise ValueError(f"threshold={threshold!r}: must be in (0, 1]")
        if zero_distance <= 0 or gospa_c <= 0 or gospa_p < 1:
            raise ValueError("zero_distance and gospa_c must be positive and gospa_p >= 1")
        self.similarity, self.threshold, self.zero_distance = similarity, threshold, zero_distance
        self.gospa_c, self.gospa_p = gospa_c, gospa_p
        self._gt_ids, self._trk_ids = IdIndex(), IdIndex()
        # CLEAR state per GT id: last-ever tracker match, previous-timestep match, frame counts
        self._last = Grow(-1, np.intp)
        self._prev = Grow(-1, np.intp)
        self._seen = Grow(0, np.int64)
        self._matched = Grow(0, np.int64)
        self._frag = Grow(0, np.int64)
        self._prev_rows = np.zeros(0, np.intp)  # GT indices whose `_prev` is set
        self.tp = self.fp = self.fn = self.idsw = 0
        self.similarity_total = 0.0
        self._log = FrameLog()  # what the global passes need of every frame
        self._occlusion = OcclusionWindows()
        self._pairs = (NO_ROWS, NO_ROWS)  # the latest frame's CLEAR matches: rows of its GT, columns of its tracks

    # ------------------------------------------------------------ per frame

    def _similarity(self, gt_boxes: np.ndarray, trk_boxes: np.ndarray) -> np.ndarray:
        if not len(gt_boxes) or not len(trk_boxes):
            return np.zeros((len(gt_boxes), len(trk_boxes)))
        if self.similarity == "iou":
            return box_iou(gt_boxes, trk_boxes)
        return np.maximum(0.0, 1.0 - centre_distance(gt_boxes, trk_boxes) / self.zero_distance)

    def update(self, gt_ids, gt_boxes, trk_ids, trk_boxes, everyone=None) -> FrameStats:
        """Score one frame: GT ids (n,) and boxes (n, 4), tracker ids (m,) and boxes (m, 4), x, y, w, h. `everyone`:
        (ids, boxes, visibility) of every target in view, hidden ones too, for the occlusion windows."""
        frame = len(self._log)
        gt_ids, gt_boxes = check_frame("gt", gt_ids, gt_boxes, f"frame {frame}")
        trk_ids, trk_boxes = check_frame("tracks", trk_ids, trk_boxes, f"frame {frame}")
        if everyone is not None:
            everyone = check_everyone(everyone, gt_ids, frame)
        stats = self._score(gt_ids, gt_boxes, trk_ids, trk_boxes)
        if everyone is not None:
            rows, cols = self._pairs
            self._occlusion.update(*everyone, trk_ids, trk_boxes, gt_ids[rows], trk_ids[cols])
        return stats

    def _score(self, gt_ids, gt_boxes, trk_ids, trk_boxes) -> FrameStats:
        """The CLEAR and per-frame work of one validated frame; its matches are left in `_pairs`."""
        self._pairs = (NO_ROWS, NO_ROWS)
        g, t = self._gt_ids(gt_ids), self._trk_ids(trk_ids)
        sim = self._similarity(gt_boxes, trk_boxes)
        self._log.add_frame(g, t, gt_boxes, trk_boxes, sim)
        if len(self._gt_ids) > len(self._seen.a):
            for arr in (self._last, self._prev, self._seen, self._matched, self._frag):
                arr.ensure(len(self._gt_ids))
        if not len(g):  # TrackEval skips the frame before resetting the previous-timestep matches
            self.fp += len(t)
            return FrameStats(0, len(t), 0, 0, 0, 0.0)
        self._seen.a[g] += 1
        if not len(t):
            self.fn += len(g)
            return FrameStats(0, 0, len(g), 0, len(g), 0.0)
        return self._clear(g, t, sim)

    def _clear(self, g: np.ndarray, t: np.ndarray, sim: np.ndarray) -> FrameStats:
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
        self._log.add_matches(rows, cols)
        self._pairs = (rows, cols)
        tp, s = len(mg), float(sim[rows, cols].sum())
        fn, fp = len(g) - tp, len(t) - tp
        self.tp, self.fp, self.fn, self.idsw = self.tp + tp, self.fp + fp, self.fn + fn, self.idsw + idsw
        self.similarity_total += s
        return FrameStats(tp, fp, fn, idsw, len(g), s)

    def __len__(self) -> int:
        """Frames scored so far."""
        return len(self._log)

    def stored_bytes(self) -> int:
        """Bytes this episode's frames are kept in (for the global passes of `summary`)."""
        return self._log.nbytes()

    def frame_gospa(self, index: int = -1) -> float:
        """GOSPA of one stored frame (default: the latest)."""
        return gospa_of_points(*self._log.points(index), self.gospa_c, self.gospa_p)

    # ------------------------------------------------------------ episode

    def summary(self) -> dict:
        """All metrics for the frames so far, as a plain dict (definitions: `mtt_sim.metrics`)."""
        num_gt_ids, num_trk_ids = len(self._gt_ids), len(self._trk_ids)
        flat = FlatSimilarities(self._log, num_gt_ids, num_trk_ids)
        seen = self._seen.ensure(num_gt_ids)[:num_gt_ids]
        ratio = self._matched.a[:num_gt_ids][seen > 0] / seen[seen > 0]
        mt = int((ratio > 0.8).sum())
        pt = int((ratio >= 0.2).sum()) - mt
        frag = self._frag.a[:num_gt_ids]
        gt_total = max(1, self.tp + self.fn)
        out = {
            "MOTA": (self.tp - self.fp - self.idsw) / gt_total,
            "MOTP": self.similarity_total / max(1, self.tp),
            "MODA": (self.tp - self.fp) / gt_total,
            "CLR_Re": self.tp / gt_total, "CLR_Pr": self.tp / max(1, self.tp + self.fp),
            "TP": self.tp, "FP": self.fp, "FN": self.fn, "IDSW": self.idsw,
            "Frag": int(np.maximum(frag[frag > 0] - 1, 0).sum()),
            "MT": mt, "PT": pt, "ML": num_gt_ids - mt - pt,
        }
        _, errors = self._match_distances()
        out["CentreError"] = float(errors.mean()) if len(errors) else 0.0
        out["CentreErrorVar"] = float(errors.var()) if len(errors) else 0.0
        out.update(identity(flat, self.threshold))
        out.update(hota(flat))
        out["GOSPA"] = self._mean_gospa()
        out.update(self._occlusion.summary())
        out.update(num_frames=len(self._log), num_gt_dets=flat.num_gt_dets, num_gt_ids=num_gt_ids,
                   num_tracker_dets=flat.num_trk_dets, num_tracker_ids=num_trk_ids)
        return {k: (float(v) if isinstance(v, (float, np.floating)) else v if v is None else int(v))
                for k, v in out.items()}

    def _mean_gospa(self) -> float:
        """The mean over frames of each frame's GOSPA."""
        if not len(self._log):
            return 0.0
        c, p = self.gospa_c, self.gospa_p
        return float(np.mean([gospa_of_points(a, b, c, p) for a, b in zip(*self._log.split_points())]))

    def _match_distances(self) -> tuple[np.ndarray, np.ndarray]:
        """(dense GT index, centre distance) of every CLEAR match so far."""
        log = self._log
        g, t = log.matches()
        return log.gt.data[g].astype(np.intp), np.linalg.norm(log.gt_xy.data[g] - log.trk_xy.data[t], axis=1)

    def per_target(self) -> dict[int, dict]:
        """Per GT id: Coverage (the fraction of its frames with a CLEAR match) and CentreError (the mean centre
        distance of those matches, nan if none): the per-target tracking error the papers plot; and its
        HiddenCentreError and Reacquired (`mtt_sim.metrics.occlusion`)."""
        n = len(self._gt_ids)
        gt, dist = self._match_distances()
        total = np.bincount(gt, dist, minlength=n)
        matched, seen = self._matched.ensure(n)[:n], self._seen.ensure(n)[:n]
        with np.errstate(invalid="ignore", divide="ignore"):
            error, coverage = total / matched, matched / np.maximum(seen, 1)
        hidden = self._occlusion.per_target()
        nothing = {"HiddenCentreError": None, "Reacquired": None}
        return {int(i): {"Coverage": float(coverage[k]), "CentreError": float(error[k]), **hidden.get(i, nothing)}
                for i, k in self._gt_ids.index.items()}


def evaluate(gt: Sequence[tuple], tracks: Sequence[tuple], similarity: str = "iou", threshold: float = 0.5,
             zero_distance: float = 2.0, gospa_c: float = 50.0, gospa_p: float = 1.0) -> dict:
    """Metrics of a whole sequence: `gt` and `tracks` are per-frame (ids, boxes) pairs of the same length."""
    gt, tracks = list(gt), list(tracks)
    if len(gt) != len(tracks):
        raise ValueError(f"gt has {len(gt)} frames but tracks has {len(tracks)}; they must be the same length")
    metrics = EpisodeMetrics(similarity, threshold, zero_distance, gospa_c, gospa_p)
    for (gi, gb), (ti, tb) in zip(gt, tracks):
        metrics.update(gi, gb, ti, tb)
    return metrics.summary()


METRICS = tuple(EpisodeMetrics().summary())  # every metric of an episode summary, in summary order
PER_TARGET = ("CentreError", "Coverage", "HiddenCentreError", "Reacquired")  # EpisodeMetrics.per_target()'s
