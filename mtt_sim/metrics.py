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
  matches, pooled over targets (the error measure of seed 000's Tables 3 and 4), in pixels.
- Similarity "iou" is the box IoU; "centroid" is TrackEval's point similarity
  max(0, 1 - d / zero_distance) on box centres.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.optimize import linear_sum_assignment

EPS = np.finfo(float).eps
HOTA_ALPHAS = np.arange(0.05, 0.99, 0.05)
SIMILARITIES = ("iou", "centroid")


def box_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU matrix (len(a), len(b)) of boxes x, y, w, h (TrackEval's guards against empty boxes)."""
    a, b = np.asarray(a, float).reshape(-1, 4), np.asarray(b, float).reshape(-1, 4)
    ax0, ay0, aw, ah = (a[:, k, None] for k in range(4))
    bx0, by0, bw, bh = b.T
    iw = np.minimum(ax0 + aw, bx0 + bw) - np.maximum(ax0, bx0)
    ih = np.minimum(ay0 + ah, by0 + bh) - np.maximum(ay0, by0)
    inter = np.maximum(iw, 0) * np.maximum(ih, 0)
    area_a, area_b = aw * ah, bw * bh
    union = area_a + area_b - inter
    if (area_a <= EPS).any() or (area_b <= EPS).any():  # only then can the union vanish
        inter[(area_a <= EPS) | (area_b <= EPS) | (union <= EPS)] = 0
        union = np.where(union <= EPS, 1.0, union)
    return inter / union


def centres(boxes: np.ndarray) -> np.ndarray:
    boxes = np.asarray(boxes, float).reshape(-1, 4)
    return boxes[:, :2] + boxes[:, 2:] / 2


def centre_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Euclidean distance matrix between box centres."""
    return np.linalg.norm(centres(a)[:, None] - centres(b)[None], axis=2)


def centre_distance_pairs(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance between the centres of boxes a[i] and b[i]."""
    return np.linalg.norm(centres(a) - centres(b), axis=1)


def gospa(a: np.ndarray, b: np.ndarray, c: float, p: float) -> float:
    """GOSPA (alpha = 2) between the centres of two sets of boxes, with cut-off c and order p."""
    if not len(a) or not len(b):
        return float((c**p / 2 * (len(a) + len(b))) ** (1 / p))
    cost = np.minimum(centre_distance(a, b), c) ** p  # assigning at distance >= c costs what leaving both does
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
    """A 1-D array that grows (doubling) as new ids appear; `fill` for new slots."""

    def __init__(self, fill, dtype):
        self.fill, self.a = fill, np.full(16, fill, dtype)

    def ensure(self, n: int) -> np.ndarray:
        if n > len(self.a):
            more = np.full(max(n, 2 * len(self.a)) - len(self.a), self.fill, self.a.dtype)
            self.a = np.concatenate([self.a, more])
        return self.a


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
        # per frame, for the global passes: dense GT and tracker ids, similarity, boxes (for GOSPA)
        self._frames: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self._matches: list[tuple[int, np.ndarray, np.ndarray]] = []  # CLEAR matches: frame, GT rows, track rows

    # ------------------------------------------------------------ per frame

    def _similarity(self, gt_boxes: np.ndarray, trk_boxes: np.ndarray) -> np.ndarray:
        if not len(gt_boxes) or not len(trk_boxes):
            return np.zeros((len(gt_boxes), len(trk_boxes)))
        if self.similarity == "iou":
            return box_iou(gt_boxes, trk_boxes)
        return np.maximum(0.0, 1.0 - centre_distance(gt_boxes, trk_boxes) / self.zero_distance)

    def update(self, gt_ids, gt_boxes, trk_ids, trk_boxes) -> FrameStats:
        """Score one frame: GT ids (n,) and boxes (n, 4), tracker ids (m,) and boxes (m, 4), x, y, w, h."""
        gt_ids, gt_boxes = _check_frame("gt", gt_ids, gt_boxes, len(self._frames))
        trk_ids, trk_boxes = _check_frame("tracks", trk_ids, trk_boxes, len(self._frames))
        g, t = self._gt_ids(gt_ids), self._trk_ids(trk_ids)
        sim = self._similarity(gt_boxes, trk_boxes)
        self._frames.append((g, t, sim, gt_boxes, trk_boxes))
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
        score = 1000.0 * (t[None, :] == prev[g][:, None]) + sim
        score[sim < self.threshold - EPS] = 0
        rows, cols = linear_sum_assignment(score, maximize=True)
        keep = score[rows, cols] > EPS
        rows, cols = rows[keep], cols[keep]
        mg, mt = g[rows], t[cols]
        before = last[mg]
        idsw = int(np.count_nonzero((before >= 0) & (before != mt)))
        self._matched.a[mg] += 1
        self._frag.a[mg] += prev[mg] < 0  # newly tracked (prev is reset below for everyone else)
        last[mg] = mt
        prev[self._prev_rows] = -1
        prev[mg] = mt
        self._prev_rows = mg
        self._matches.append((len(self._frames) - 1, rows, cols))
        tp, s = len(mg), float(sim[rows, cols].sum())
        fn, fp = len(g) - tp, len(t) - tp
        self.tp, self.fp, self.fn, self.idsw = self.tp + tp, self.fp + fp, self.fn + fn, self.idsw + idsw
        self.similarity_total += s
        return FrameStats(tp, fp, fn, idsw, len(g), s)

    def frame_gospa(self, index: int = -1) -> float:
        """GOSPA of one stored frame (default: the latest)."""
        _, _, _, gt_boxes, trk_boxes = self._frames[index]
        return gospa(gt_boxes, trk_boxes, self.gospa_c, self.gospa_p)

    # ------------------------------------------------------------ episode

    def summary(self) -> dict:
        """All metrics for the frames so far, as a plain dict (see the module docstring for definitions)."""
        num_gt_ids, num_trk_ids = len(self._gt_ids), len(self._trk_ids)
        flat = _Flat(self._frames, num_gt_ids, num_trk_ids)
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
        out.update(_hota(flat, self._frames))
        out["GOSPA"] = float(np.mean([self.frame_gospa(i) for i in range(len(self._frames))])) if self._frames else 0.0
        out.update(num_frames=len(self._frames), num_gt_dets=flat.num_gt_dets, num_gt_ids=num_gt_ids,
                   num_tracker_dets=flat.num_trk_dets, num_tracker_ids=num_trk_ids)
        return {k: (float(v) if isinstance(v, (float, np.floating)) else int(v)) for k, v in out.items()}

    def _match_distances(self) -> tuple[np.ndarray, np.ndarray]:
        """(dense GT index, centre distance) of every CLEAR match so far."""
        pairs = [(self._frames[f][0][r], centre_distance_pairs(self._frames[f][3][r], self._frames[f][4][c]))
                 for f, r, c in self._matches]
        return tuple(np.concatenate(x) for x in zip(*pairs)) if pairs else (np.zeros(0, np.intp), np.zeros(0))

    def per_target(self) -> dict[int, dict]:
        """Per GT id: Coverage (the fraction of its frames with a CLEAR match) and CentreError (the mean centre
        distance of those matches, nan if none): the per-target tracking error the papers plot."""
        n = len(self._gt_ids)
        gt, dist = self._match_distances()
        total = np.bincount(gt, dist, minlength=n)
        matched, seen = self._matched.ensure(n)[:n], self._seen.ensure(n)[:n]
        with np.errstate(invalid="ignore", divide="ignore"):
            error, coverage = total / matched, matched / np.maximum(seen, 1)
        return {int(i): {"Coverage": float(coverage[k]), "CentreError": float(error[k])}
                for i, k in self._gt_ids.index.items()}

    def _identity(self, flat: "_Flat") -> dict:
        """IDTP = the largest number of frames a one-to-one GT-to-tracker id assignment can match."""
        hit = flat.sim >= self.threshold
        idtp = 0
        if hit.any():
            (_, gi), (_, ti) = (np.unique(ids[hit], return_inverse=True) for ids in (flat.gt, flat.trk))
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
    count towards either, so only the nonzero entries are kept (`dense` is every frame's matrix, raveled).
    """

    def __init__(self, frames: list, num_gt_ids: int, num_trk_ids: int):
        n = np.array([len(f[0]) for f in frames], np.int64).reshape(-1)
        m = np.array([len(f[1]) for f in frames], np.int64).reshape(-1)
        self.n, self.m, sizes = n, m, n * m
        self.start = np.cumsum(sizes) - sizes
        empty = np.zeros(0, np.intp)
        gcat = np.concatenate([f[0] for f in frames] or [empty])
        tcat = np.concatenate([f[1] for f in frames] or [empty])
        self.dense = np.concatenate([f[2].ravel() for f in frames] or [np.zeros(0)])
        self.idx = np.flatnonzero(self.dense)
        self.sim = self.dense[self.idx]
        frame = np.searchsorted(self.start, self.idx, side="right") - 1
        local = self.idx - self.start[frame]
        self.row = (np.cumsum(n) - n)[frame] + local // m[frame]  # index into the concatenated GT ids
        self.col = (np.cumsum(m) - m)[frame] + local % m[frame]   # index into the concatenated tracker ids
        self.gt, self.trk = gcat[self.row], tcat[self.col]
        self.gt_count = np.bincount(gcat, minlength=num_gt_ids)
        self.trk_count = np.bincount(tcat, minlength=num_trk_ids)
        self.num_gt_dets, self.num_trk_dets = len(gcat), len(tcat)


def _hota(flat: _Flat, frames: list) -> dict:
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
    score = np.zeros_like(flat.dense)
    score[flat.idx] = (potential / (gc + tc - potential))[pair] * sim
    # pass 2: per frame, the assignment maximising alignment x similarity
    matched = []
    for k in np.flatnonzero(flat.n * flat.m):
        n, m, start = int(flat.n[k]), int(flat.m[k]), int(flat.start[k])
        rows, cols = linear_sum_assignment(score[start: start + n * m].reshape(n, m), maximize=True)
        matched.append(start + rows * m + cols)
    idx = np.concatenate(matched) if matched else np.zeros(0, np.intp)
    idx = idx[flat.dense[idx] > 0]  # a match of zero similarity counts at no alpha
    s = flat.dense[idx]
    hit = s[None, :] >= HOTA_ALPHAS[:, None] - EPS  # (alphas, matches)
    tp = hit.sum(axis=1).astype(float)
    fn, fp = flat.num_gt_dets - tp, flat.num_trk_dets - tp
    loc = (hit * s).sum(axis=1)
    a_idx, m_idx = np.nonzero(hit)
    matched_pair = pair[np.searchsorted(flat.idx, idx)]
    combos, counts = np.unique(a_idx * len(pair_keys) + matched_pair[m_idx], return_counts=True)
    a, p = combos // max(len(pair_keys), 1), combos % max(len(pair_keys), 1)
    ass_a, ass_re, ass_pr = (np.zeros(n_alpha) for _ in range(3))
    for out, d in ((ass_a, gc[p] + tc[p] - counts), (ass_re, gc[p]), (ass_pr, tc[p])):
        np.add.at(out, a, counts * counts / np.maximum(1, d))
        out /= np.maximum(1, tp)
    det_a = tp / np.maximum(1, tp + fn + fp)
    hota = np.sqrt(det_a * ass_a)
    loc_a = np.maximum(1e-10, loc) / np.maximum(1e-10, tp)
    return {"HOTA": hota.mean(), "DetA": det_a.mean(), "AssA": ass_a.mean(), "LocA": loc_a.mean(),
            "DetRe": (tp / np.maximum(1, tp + fn)).mean(), "DetPr": (tp / np.maximum(1, tp + fp)).mean(),
            "AssRe": ass_re.mean(), "AssPr": ass_pr.mean(), "HOTA(0)": hota[0], "LocA(0)": loc_a[0]}


def _check_frame(what: str, ids, boxes, frame: int) -> tuple[np.ndarray, np.ndarray]:
    """Validated (ids int64 (n,), boxes float64 (n, 4)) of one frame, or a ValueError naming the problem."""
    ids, boxes = np.asarray(ids), np.asarray(boxes, dtype=float)
    if ids.size == 0 and boxes.size == 0:
        return np.zeros(0, np.int64), np.zeros((0, 4))
    if ids.ndim != 1 or boxes.shape != (len(ids), 4):
        raise ValueError(f"frame {frame}: {what} ids must have shape (n,) and boxes (n, 4), got {ids.shape} and {boxes.shape}")
    if ids.dtype.kind not in "iu":
        raise ValueError(f"frame {frame}: {what} ids must be integers, got dtype {ids.dtype}")
    if not np.isfinite(boxes).all():
        raise ValueError(f"frame {frame}: {what} boxes must be finite; row {int(np.flatnonzero(~np.isfinite(boxes).all(1))[0])} is not")
    if len(set(ids.tolist())) != len(ids):
        raise ValueError(f"frame {frame}: {what} ids must be unique within a frame")
    return ids.astype(np.int64), boxes


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

