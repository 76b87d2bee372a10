"""The global passes over a whole episode: identity (IDF1, IDP, IDR) and HOTA, both on the nonzero similarities of
every frame laid out flat (definitions: `mtt_sim.metrics`)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from mtt_sim.boxes import EPS
from mtt_sim.metrics.frame_log import FrameLog

HOTA_ALPHAS = np.arange(0.05, 0.99, 0.05)


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


def identity(flat: FlatSimilarities, threshold: float) -> dict:
    """IDTP = the largest number of frames a one-to-one GT-to-tracker id assignment can match."""
    hit = flat.sim >= threshold
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


def _ranks(ids: np.ndarray, size: int) -> np.ndarray:
    """Each id's rank among the distinct ids present (np.unique's inverse, for ids in 0..size-1, without sorting)."""
    present = np.zeros(size, bool)
    present[ids] = True
    return (np.cumsum(present) - 1)[ids]


def hota(flat: FlatSimilarities) -> dict:
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
    hota_a = np.sqrt(det_a * ass_a)
    loc_a = np.maximum(1e-10, loc) / np.maximum(1e-10, tp)
    return {"HOTA": hota_a.mean(), "DetA": det_a.mean(), "AssA": ass_a.mean(), "LocA": loc_a.mean(),
            "DetRe": (tp / np.maximum(1, tp + fn)).mean(), "DetPr": (tp / np.maximum(1, tp + fp)).mean(),
            "AssRe": ass_re.mean(), "AssPr": ass_pr.mean(), "HOTA(0)": hota_a[0], "LocA(0)": loc_a[0]}
