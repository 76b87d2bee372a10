"""Multi-object tracking metrics, as TrackEval (the MOTChallenge reference) computes them.

`EpisodeMetrics.update` takes one frame of ground truth and tracks and does the per-frame work
at once (similarities, the CLEAR matching, identity and HOTA counts); `summary` finishes the global
parts (the IDF1 assignment, HOTA's second pass, GOSPA). `evaluate` runs both on a whole sequence.

Semantics, following TrackEval where other tools differ:

- CLEAR (MOTA, MOTP, IDSW, Frag, MT/PT/ML). Per frame, pairs with similarity >= threshold (0.5) are
  matched by a Hungarian assignment maximising similarity plus a bonus of 1000 for keeping each GT
  id's match of the *previous timestep*. An IDSW is counted when a GT id is matched to a tracker id
  other than its *last-ever* match (py-motmetrics differs in what it carries over).
  A frame with no GT or no tracks is skipped before the carry-over is reset, as in TrackEval: a
  match survives such a frame for both the bonus and Frag (py-motmetrics differs).
  Frag counts, per GT id, the times it goes from not tracked to tracked, minus one.
  MT: tracked in > 80 % of its frames; PT: >= 20 % and not MT; ML: the rest (py-motmetrics: >= 80 %).
  MOTA = (TP - FP - IDSW) / max(1, TP + FN); MOTP = mean similarity of the matches.
- Identity (IDF1, IDP, IDR): the global one-to-one assignment of GT ids to tracker ids that
  maximises the number of frames in which the pair has similarity >= threshold. TrackEval solves
  it on an augmented (G + T) square cost matrix; maximising the matched count on the G x T matrix of
  ids that have any potential match is the same optimum.
- HOTA over alpha = 0.05, 0.10, ..., 0.95: DetA, AssA (and DetRe, DetPr, AssRe, AssPr) per alpha,
  LocA = mean similarity of matches per alpha; HOTA = sqrt(DetA * AssA); reported values are the
  means over the 19 alphas.
- GOSPA (alpha = 2) on box centres with cut-off `c` and order `p`, computed with an exact
  assignment: (sum over assigned pairs of min(d, c)^p + c^p / 2 * (missed + false))^(1/p); the mean
  over frames is reported.
- CentreError and CentreErrorVar: mean and variance of the distance between the box centres of the CLEAR
  matches, pooled over targets (the error measure of the JPDA paper's Tables 3 and 4), in pixels.
- Similarity "iou" is the box IoU; "centroid" is TrackEval's point similarity
  max(0, 1 - d / zero_distance) on box centres.
- Occlusion windows (scenes whose truth is passed to `update` as `everyone`; None, 0 otherwise). A target is
  *hidden* in a frame where its visibility is below HIDDEN (0.05); its *holder* is the track CLEAR-matched to it
  in the latest frame it was matched (none before its first match).
  HiddenCentreError: the mean distance in pixels between a hidden target's box centre and its holder's reported
  box centre, over the hidden frames in which the holder is reported.
  An *occlusion* begins at a hidden frame of a target that has a holder and no occlusion under way; it is
  *revealed* at the first later frame where the target is at least REVEALED (0.5) visible, and *re-acquired* if
  its holder at the beginning is CLEAR-matched to the target in one of the WINDOW (20) frames from that one on.
  An occlusion is decided when its window has passed. Reacquired: the share re-acquired among those decided;
  Occlusions: how many were decided. One whose window the episode cuts short is not counted, re-acquired or not,
  so that where an episode ends favours no tracker. HiddenCentreError and Reacquired are None where nothing was
  counted.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.optimize import linear_sum_assignment

from mtt_sim.boxes import EPS, box_iou, centre_distance, centres, check_frame, match, rows_of
HIDDEN, REVEALED, WINDOW = 0.05, 0.5, 20  # the occlusion windows' visibilities and frames (module docstring)
_CLEAR, _HIDDEN, _WINDOW = 0, 1, 2  # a target's occlusion: none under way, hidden and not yet revealed, in its window
HOTA_ALPHAS = np.arange(0.05, 0.99, 0.05)
SIMILARITIES = ("iou", "centroid")


def gospa(a: np.ndarray, b: np.ndarray, c: float, p: float) -> float:
    """GOSPA (alpha = 2) between the centres of two sets of boxes, with cut-off c and order p."""
    return gospa_of_points(centres(a), centres(b), c, p)


def gospa_of_points(a: np.ndarray, b: np.ndarray, c: float, p: float) -> float:
    """GOSPA (alpha = 2) between two point sets (n, 2) and (m, 2), with cut-off c and order p."""
    if not len(a) or not len(b):
        return float((c**p / 2 * (len(a) + len(b))) ** (1 / p))
    dx, dy = a[:, 0, None] - b[None, :, 0], a[:, 1, None] - b[None, :, 1]
    cost = np.minimum(np.sqrt(dx * dx + dy * dy), c) ** p  # assigning at >= c costs what leaving both does
    rows, cols = linear_sum_assignment(cost)
    return float((cost[rows, cols].sum() + c**p / 2 * abs(len(a) - len(b))) ** (1 / p))


@dataclass(frozen=True)
class FrameStats:
    """CLEAR counts of one frame (what the per-step rewards are made of)."""

    tp: int
    fp: int
    fn: int
    idsw: int
    num_gt: int
    similarity_sum: float  # summed similarity of the matched pairs


class _IdIndex:
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


class _Grow:
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


class _Log(_Grow):
    """An append-only `_Grow` (growing by a quarter, so at most a fifth of it is unused)."""

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


_NONE = np.zeros(0, np.intp)


class _Episode:
    """What the global passes need of every frame, stored compactly in a few flat logs: the dense GT and tracker ids,
    their box centres (GOSPA, centre errors), the nonzero similarities (row, column, value: the only pairs identity and
    HOTA count) and the CLEAR matches, and per frame the counts n, m, nonzeros and matches (about 15 KB a frame at
    200 objects, where the similarity matrix alone is 320 KB). Frames wait in a short list and join the logs in
    batches, so a frame costs a few appends to a list."""

    BATCH = 256

    def __init__(self):
        self._waiting: list[list] = []  # per frame: g, t, gt boxes, track boxes, rows, cols, sims, match rows, match cols
        self.counts = _Log(np.int64, 4)
        self.gt, self.trk = _Log(np.int32), _Log(np.int32)
        self.gt_xy, self.trk_xy = _Log(np.float64, 2), _Log(np.float64, 2)
        self.nz_row, self.nz_col, self.nz_sim = _Log(np.int32), _Log(np.int32), _Log(np.float64)
        self.match_row, self.match_col = _Log(np.int32), _Log(np.int32)

    def add_frame(self, g: np.ndarray, t: np.ndarray, gt_boxes: np.ndarray, trk_boxes: np.ndarray, sim: np.ndarray):
        if len(self._waiting) >= self.BATCH:
            self.flush()
        rows, cols = np.nonzero(sim > 0)  # similarities are never negative; a boolean scan is twice as fast
        self._waiting.append([g, t, gt_boxes, trk_boxes, rows, cols, sim[rows, cols], _NONE, _NONE])

    def add_matches(self, rows: np.ndarray, cols: np.ndarray):
        """The CLEAR matches (row and column indices within the frame) of the latest frame."""
        self._waiting[-1][7:] = rows, cols

    def flush(self) -> "_Episode":
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
        return sum(log.a.nbytes for log in vars(self.flush()).values() if isinstance(log, _Log))

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


class _OcclusionWindows:
    """The occlusion-window measures (module docstring), kept per target id in growing arrays."""

    def __init__(self):
        self.ids = _IdIndex()
        self.holder = _Grow(-1, np.int64)      # tracker id of the latest match
        self.stage = _Grow(_CLEAR, np.int8)    # where each target's occlusion stands
        self.owed = _Grow(-1, np.int64)        # the holder an occlusion under way waits for
        self.deadline = _Grow(-1, np.int64)    # the last frame of its window
        self.won = _Grow(False, bool)          # whether the holder has matched the target in the window so far
        self.error = _Grow(0.0, float, 2)      # summed hidden centre error, frames counted
        self.decided = _Grow(0, np.int64, 2)   # occlusions re-acquired, occlusions decided
        self.frame = -1

    def update(self, ids, boxes, visibility, trk_ids, trk_boxes, matched_gt, matched_trk) -> None:
        """One frame: every target in view (ids, boxes, visibility), the reported tracks, the CLEAR matches. Most
        frames have nobody hidden and no occlusion under way: they only note who holds whom."""
        self.frame += 1
        g = self.ids(ids)
        n = len(self.ids)
        holder, stage = self.holder.ensure(n), self.stage.ensure(n)
        matched_to = np.full(n, -1, np.int64)
        matched_to[self.ids(matched_gt)] = matched_trk
        if (visibility < HIDDEN).any() or stage[:n].any():
            self._windows(g, boxes, visibility, trk_ids, trk_boxes, matched_to)
        now = np.flatnonzero(matched_to >= 0)
        holder[now] = matched_to[now]

    def _windows(self, g, boxes, visibility, trk_ids, trk_boxes, matched_to) -> None:
        """Open, reveal and decide occlusions, and add the hidden frames' centre errors."""
        n = len(self.ids)
        holder, stage, owed, deadline, won = (a.ensure(n) for a in (self.holder, self.stage, self.owed, self.deadline,
                                                                     self.won))
        error, decided = self.error.ensure(n), self.decided.ensure(n)
        revealed = g[(stage[g] == _HIDDEN) & (visibility >= REVEALED)]
        stage[revealed], deadline[revealed] = _WINDOW, self.frame + WINDOW - 1
        waiting = np.flatnonzero(stage[:n] == _WINDOW)
        won[waiting] |= matched_to[waiting] == owed[waiting]
        over = waiting[deadline[waiting] <= self.frame]  # decided when the window has passed, won or not
        decided[over, 0] += won[over]
        decided[over, 1] += 1
        stage[over], won[over] = _CLEAR, False
        at = np.flatnonzero((visibility < HIDDEN) & (holder[g] >= 0))  # rows of the hidden targets with a holder
        held = g[at]
        starting = held[stage[held] == _CLEAR]
        stage[starting], owed[starting] = _HIDDEN, holder[starting]
        row = rows_of(trk_ids, holder[held])  # each holder's row among the reported tracks, -1 if not reported
        seen = row >= 0
        if seen.any():
            d = np.linalg.norm(centres(boxes[at[seen]]) - centres(trk_boxes[row[seen]]), axis=1)
            error[held[seen], 0] += d
            error[held[seen], 1] += 1

    def summary(self) -> dict:
        n = len(self.ids)
        error, decided = self.error.ensure(n)[:n].sum(axis=0), self.decided.ensure(n)[:n].sum(axis=0)
        return {"HiddenCentreError": _ratio(error[0], error[1]), "Reacquired": _ratio(decided[0], decided[1]),
                "Occlusions": int(decided[1])}

    def per_target(self) -> dict[int, dict]:
        n = len(self.ids)
        error, decided = self.error.ensure(n), self.decided.ensure(n)
        return {i: {"HiddenCentreError": _ratio(error[k, 0], error[k, 1]),
                    "Reacquired": _ratio(decided[k, 0], decided[k, 1])} for i, k in self.ids.index.items()}


def _ratio(a: float, b: float) -> float | None:
    """a / b, or None (no value: nothing was counted) when b is 0."""
    return float(a / b) if b else None


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
        self._gt_ids, self._trk_ids = _IdIndex(), _IdIndex()
        # CLEAR state per GT id: last-ever tracker match, previous-timestep match, frame counts
        self._last = _Grow(-1, np.intp)
        self._prev = _Grow(-1, np.intp)
        self._seen = _Grow(0, np.int64)
        self._matched = _Grow(0, np.int64)
        self._frag = _Grow(0, np.int64)
        self._prev_rows = np.zeros(0, np.intp)  # GT indices whose `_prev` is set
        self.tp = self.fp = self.fn = self.idsw = 0
        self.similarity_total = 0.0
        self._episode = _Episode()  # what the global passes need of every frame
        self._occlusion = _OcclusionWindows()
        self._pairs = (_NONE, _NONE)  # the latest frame's CLEAR matches: rows of its GT, columns of its tracks

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
        frame = len(self._episode)
        gt_ids, gt_boxes = check_frame("gt", gt_ids, gt_boxes, f"frame {frame}")
        trk_ids, trk_boxes = check_frame("tracks", trk_ids, trk_boxes, f"frame {frame}")
        if everyone is not None:
            everyone = _check_everyone(everyone, gt_ids, frame)
        stats = self._score(gt_ids, gt_boxes, trk_ids, trk_boxes)
        if everyone is not None:
            rows, cols = self._pairs
            self._occlusion.update(*everyone, trk_ids, trk_boxes, gt_ids[rows], trk_ids[cols])
        return stats

    def _score(self, gt_ids, gt_boxes, trk_ids, trk_boxes) -> FrameStats:
        """The CLEAR and per-frame work of one validated frame; its matches are left in `_pairs`."""
        self._pairs = (_NONE, _NONE)
        g, t = self._gt_ids(gt_ids), self._trk_ids(trk_ids)
        sim = self._similarity(gt_boxes, trk_boxes)
        self._episode.add_frame(g, t, gt_boxes, trk_boxes, sim)
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
        self._episode.add_matches(rows, cols)
        self._pairs = (rows, cols)
        tp, s = len(mg), float(sim[rows, cols].sum())
        fn, fp = len(g) - tp, len(t) - tp
        self.tp, self.fp, self.fn, self.idsw = self.tp + tp, self.fp + fp, self.fn + fn, self.idsw + idsw
        self.similarity_total += s
        return FrameStats(tp, fp, fn, idsw, len(g), s)

    def __len__(self) -> int:
        """Frames scored so far."""
        return len(self._episode)

    def stored_bytes(self) -> int:
        """Bytes this episode's frames are kept in (for the global passes of `summary`)."""
        return self._episode.nbytes()

    def frame_gospa(self, index: int = -1) -> float:
        """GOSPA of one stored frame (default: the latest)."""
        return gospa_of_points(*self._episode.points(index), self.gospa_c, self.gospa_p)

    # ------------------------------------------------------------ episode

    def summary(self) -> dict:
        """All metrics for the frames so far, as a plain dict (see the module docstring for definitions)."""
        num_gt_ids, num_trk_ids = len(self._gt_ids), len(self._trk_ids)
        flat = _Flat(self._episode, num_gt_ids, num_trk_ids)
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
        out.update(self._identity(flat))
        out.update(_hota(flat))
        out["GOSPA"] = self._mean_gospa()
        out.update(self._occlusion.summary())
        out.update(num_frames=len(self._episode), num_gt_dets=flat.num_gt_dets, num_gt_ids=num_gt_ids,
                   num_tracker_dets=flat.num_trk_dets, num_tracker_ids=num_trk_ids)
        return {k: (float(v) if isinstance(v, (float, np.floating)) else v if v is None else int(v))
                for k, v in out.items()}

    def _mean_gospa(self) -> float:
        """The mean over frames of each frame's GOSPA."""
        if not len(self._episode):
            return 0.0
        c, p = self.gospa_c, self.gospa_p
        return float(np.mean([gospa_of_points(a, b, c, p) for a, b in zip(*self._episode.split_points())]))

    def _match_distances(self) -> tuple[np.ndarray, np.ndarray]:
        """(dense GT index, centre distance) of every CLEAR match so far."""
        ep = self._episode
        g, t = ep.matches()
        return ep.gt.data[g].astype(np.intp), np.linalg.norm(ep.gt_xy.data[g] - ep.trk_xy.data[t], axis=1)

    def per_target(self) -> dict[int, dict]:
        """Per GT id: Coverage (the fraction of its frames with a CLEAR match) and CentreError (the mean centre
        distance of those matches, nan if none): the per-target tracking error the papers plot; and its
        HiddenCentreError and Reacquired (module docstring)."""
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

    def _identity(self, flat: "_Flat") -> dict:
        """IDTP = the largest number of frames a one-to-one GT-to-tracker id assignment can match."""
        hit = flat.sim >= self.threshold
        idtp = 0
        if hit.any():
            gi, ti = _ranks(flat.gt[hit], len(flat.gt_count)), _ranks(flat.trk[hit], len(flat.trk_count))
            potential = np.zeros((gi.max() + 1, ti.max() + 1))
            np.add.at(potential, (gi, ti), 1)
            rows, cols = linear_sum_assignment(potential, maximize=True)
            idtp = int(potential[rows, cols].sum())
        idfn, idfp = flat.num_gt_dets - idtp, flat.num_trk_dets - idtp
        return {"IDF1": idtp / max(1, idtp + 0.5 * idfp + 0.5 * idfn), "IDP": idtp / max(1, idtp + idfp),
                "IDR": idtp / max(1, idtp + idfn), "IDTP": idtp, "IDFP": idfp, "IDFN": idfn}


class _Flat:
    """The nonzero similarities of every frame as flat arrays, with each one's GT id and tracker id.

    This lets the global passes (identity, HOTA) run as a handful of vectorised operations over the
    whole episode instead of a Python loop of small ones per frame; pairs of zero similarity never
    count towards either. Entries run frame by frame, row-major within a frame (as np.nonzero gives them).
    """

    def __init__(self, ep: _Episode, num_gt_ids: int, num_trk_ids: int):
        starts, counts = ep.starts(), ep.counts.data
        self.n, self.m, self.nnz = counts[:, 0], counts[:, 1], counts[:, 2]
        self.frame = np.repeat(np.arange(len(ep)), self.nnz)  # each entry's frame
        self.local_row, self.local_col = ep.nz_row.data, ep.nz_col.data
        self.row = starts[self.frame, 0] + self.local_row  # index into the episode's GT rows
        self.col = starts[self.frame, 1] + self.local_col  # index into the episode's tracker rows
        self.sim = ep.nz_sim.data
        gcat, tcat = ep.gt.data, ep.trk.data
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


def _ranks(ids: np.ndarray, size: int) -> np.ndarray:
    """Each id's rank among the distinct ids present (np.unique's inverse, for ids in 0..size-1, without sorting)."""
    present = np.zeros(size, bool)
    present[ids] = True
    return (np.cumsum(present) - 1)[ids]


def _hota(flat: _Flat) -> dict:
    """HOTA (TrackEval): global alignment from similarity-normalised co-occurrence, then per-frame matching."""
    sim, n_alpha = flat.sim, len(HOTA_ALPHAS)
    # pass 1: each pair's similarity normalised by its row and column sums (a soft IoU of the two tracks)
    row_sum = np.bincount(flat.row, weights=sim, minlength=flat.num_gt_dets)
    col_sum = np.bincount(flat.col, weights=sim, minlength=flat.num_trk_dets)
    denom = row_sum[flat.row] + col_sum[flat.col] - sim
    soft = np.where(denom > EPS, sim / np.where(denom > EPS, denom, 1.0), 0.0)
    n_trk = max(len(flat.trk_count), 1)
    pair_keys, pair = np.unique(flat.gt.astype(np.int64) * n_trk + flat.trk, return_inverse=True)
    potential = np.bincount(pair, weights=soft, minlength=len(pair_keys))
    gc, tc = flat.gt_count[pair_keys // n_trk], flat.trk_count[pair_keys % n_trk]
    score = (potential / (gc + tc - potential))[pair] * sim
    # pass 2: per frame, the assignment maximising alignment x similarity. Where no row or column holds two nonzero
    # entries, any optimal assignment takes every entry, so only the crowded frames need one solved.
    crowded = flat.crowded()
    chosen = ~crowded[flat.frame]
    bounds = np.r_[0, np.cumsum(flat.nnz)]
    for k in np.flatnonzero(crowded).tolist():
        e0, e1, shape = bounds[k], bounds[k + 1], (flat.n[k], flat.m[k])
        r, c = flat.local_row[e0:e1], flat.local_col[e0:e1]
        dense, entry = np.zeros(shape), np.full(shape, -1)
        dense[r, c], entry[r, c] = score[e0:e1], np.arange(e0, e1)
        picked = entry[linear_sum_assignment(dense, maximize=True)]
        chosen[picked[picked >= 0]] = True  # a match of zero similarity counts at no alpha
    idx = np.flatnonzero(chosen)  # frame by frame, by row within a frame, as TrackEval's loop gives them
    s, matched_pair = sim[idx], pair[idx]
    # per alpha (one at a time, so memory stays at a few arrays of the matches): TP, summed similarity, and the
    # association scores from each pair's matched count; sums run in the order TrackEval's arrays give them
    tp, loc, ass_a, ass_re, ass_pr = (np.zeros(n_alpha) for _ in range(5))
    for a, alpha in enumerate(HOTA_ALPHAS):
        hit = s >= alpha - EPS
        tp[a], loc[a] = np.count_nonzero(hit), np.where(hit, s, 0.0).sum()
        counts = np.bincount(matched_pair[hit], minlength=len(pair_keys))
        p = np.flatnonzero(counts)
        counts = counts[p]
        for out, d in ((ass_a, gc[p] + tc[p] - counts), (ass_re, gc[p]), (ass_pr, tc[p])):
            out[a] = np.cumsum(counts * counts / np.maximum(1, d))[-1] if len(p) else 0.0
    for out in (ass_a, ass_re, ass_pr):
        out /= np.maximum(1, tp)
    fn, fp = flat.num_gt_dets - tp, flat.num_trk_dets - tp
    det_a = tp / np.maximum(1, tp + fn + fp)
    hota = np.sqrt(det_a * ass_a)
    loc_a = np.maximum(1e-10, loc) / np.maximum(1e-10, tp)
    return {"HOTA": hota.mean(), "DetA": det_a.mean(), "AssA": ass_a.mean(), "LocA": loc_a.mean(),
            "DetRe": (tp / np.maximum(1, tp + fn)).mean(), "DetPr": (tp / np.maximum(1, tp + fp)).mean(),
            "AssRe": ass_re.mean(), "AssPr": ass_pr.mean(), "HOTA(0)": hota[0], "LocA(0)": loc_a[0]}


def _check_everyone(everyone, gt_ids, frame: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validated (ids, boxes, visibility) of every target in view, or a ValueError naming the problem."""
    try:
        ids, boxes, visibility = everyone
    except (TypeError, ValueError):
        raise ValueError(f"frame {frame}: everyone must be (ids, boxes, visibility) of every target in view") from None
    ids, boxes = check_frame("everyone", ids, boxes, f"frame {frame}")
    visibility = np.asarray(visibility, float)
    if visibility.shape != ids.shape or not np.isfinite(visibility).all():
        raise ValueError(f"frame {frame}: everyone's visibility must be {ids.shape} finite numbers, got shape "
                         f"{visibility.shape}")
    missing = set(np.asarray(gt_ids).tolist()) - set(ids.tolist())
    if missing:
        raise ValueError(f"frame {frame}: everyone must include every scored ground-truth id; missing "
                         f"{sorted(missing)}")
    return ids, boxes, visibility


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
