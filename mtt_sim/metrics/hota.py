"""HOTA (TrackEval): a global alignment of GT and tracker ids from their similarity-normalised co-occurrence over the
whole episode, then a per-frame matching, at 19 thresholds alpha (definitions: `mtt_sim.metrics`)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from mtt_sim.boxes import EPS
from mtt_sim.metrics.family import Field, LogPass

HOTA_ALPHAS = np.arange(0.05, 0.99, 0.05)


class Hota(LogPass):
    """HOTA, DetA, AssA, LocA (and their recall and precision parts) averaged over the alphas, and HOTA and LocA at
    the lowest alpha; a pass over the nonzero similarities of every frame laid out flat."""

    FIELDS = (*(Field(name, printed=True) for name in ("HOTA", "DetA", "AssA", "LocA")),
              *(Field(name) for name in ("DetRe", "DetPr", "AssRe", "AssPr", "HOTA(0)", "LocA(0)")))

    def summary(self) -> dict:
        flat = self.log.flat()
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
