"""A plain, dense re-statement of TrackEval's CLEAR, Identity and HOTA definitions, for cross-checking.

Written for clarity, not speed: dense id x id matrices, NaN carry-over, TrackEval's augmented
(G + T) identity cost matrix. `mtt_sim.metrics` computes the same numbers incrementally and sparsely.
"""

import numpy as np
from scipy.optimize import linear_sum_assignment

EPS = np.finfo(float).eps


def iou(a, b):
    a, b = np.asarray(a, float).reshape(-1, 4), np.asarray(b, float).reshape(-1, 4)
    out = np.zeros((len(a), len(b)))
    for i, (ax, ay, aw, ah) in enumerate(a):
        for j, (bx, by, bw, bh) in enumerate(b):
            iw = max(0.0, min(ax + aw, bx + bw) - max(ax, bx))
            ih = max(0.0, min(ay + ah, by + bh) - max(ay, by))
            union = aw * ah + bw * bh - iw * ih
            out[i, j] = iw * ih / union if union > EPS and aw * ah > EPS and bw * bh > EPS else 0.0
    return out


def _dense(gt, tracks):
    """TrackEval's input: ids renumbered 0..n-1 over the sequence, similarity per frame."""
    gmap = {i: k for k, i in enumerate(dict.fromkeys(int(i) for ids, _ in gt for i in ids))}
    tmap = {i: k for k, i in enumerate(dict.fromkeys(int(i) for ids, _ in tracks for i in ids))}
    g = [np.array([gmap[int(i)] for i in ids], int) for ids, _ in gt]
    t = [np.array([tmap[int(i)] for i in ids], int) for ids, _ in tracks]
    sims = [iou(gb, tb) for (_, gb), (_, tb) in zip(gt, tracks)]
    return g, t, sims, len(gmap), len(tmap)


def clear(g_frames, t_frames, sims, num_gt_ids, thr=0.5):
    tp = fn = fp = idsw = 0
    motp = 0.0
    gt_count, matched, frag = np.zeros(num_gt_ids), np.zeros(num_gt_ids), np.zeros(num_gt_ids)
    prev_any, prev_ts = np.full(num_gt_ids, np.nan), np.full(num_gt_ids, np.nan)
    for g, t, sim in zip(g_frames, t_frames, sims):
        if len(g) == 0:
            fp += len(t)
            continue
        if len(t) == 0:
            fn += len(g)
            gt_count[g] += 1
            continue
        score = 1000 * (t[None, :] == prev_ts[g][:, None]) + sim
        score[sim < thr - EPS] = 0
        r, c = linear_sum_assignment(-score)
        ok = score[r, c] > EPS
        r, c = r[ok], c[ok]
        mg, mt = g[r], t[c]
        before = prev_any[mg]
        idsw += int(np.sum(~np.isnan(before) & (mt != before)))
        gt_count[g] += 1
        matched[mg] += 1
        was_untracked = np.isnan(prev_ts)
        prev_any[mg] = mt
        prev_ts[:] = np.nan
        prev_ts[mg] = mt
        frag += was_untracked & ~np.isnan(prev_ts)
        tp += len(mg)
        fn += len(g) - len(mg)
        fp += len(t) - len(mg)
        motp += sim[r, c].sum()
    ratio = matched[gt_count > 0] / gt_count[gt_count > 0]
    mt_ = int(np.sum(ratio > 0.8))
    pt = int(np.sum(ratio >= 0.2)) - mt_
    return {"TP": tp, "FN": fn, "FP": fp, "IDSW": idsw, "MOTA": (tp - fp - idsw) / max(1, tp + fn),
            "MOTP": motp / max(1, tp), "MT": mt_, "PT": pt, "ML": num_gt_ids - mt_ - pt,
            "Frag": int(np.sum(frag[frag > 0] - 1))}


def identity(g_frames, t_frames, sims, ng, nt, thr=0.5):
    pot, gc, tc = np.zeros((ng, nt)), np.zeros(ng), np.zeros(nt)
    for g, t, sim in zip(g_frames, t_frames, sims):
        r, c = np.nonzero(sim >= thr)
        pot[g[r], t[c]] += 1
        gc[g] += 1
        tc[t] += 1
    if gc.sum() == 0 or tc.sum() == 0:
        idtp = 0
    else:
        fp_mat, fn_mat = np.zeros((ng + nt, ng + nt)), np.zeros((ng + nt, ng + nt))
        fp_mat[ng:, :nt] = 1e10
        fn_mat[:ng, nt:] = 1e10
        for i in range(ng):
            fn_mat[i, :nt] = gc[i]
            fn_mat[i, nt + i] = gc[i]
        for j in range(nt):
            fp_mat[:ng, j] = tc[j]
            fp_mat[j + ng, j] = tc[j]
        fn_mat[:ng, :nt] -= pot
        fp_mat[:ng, :nt] -= pot
        r, c = linear_sum_assignment(fn_mat + fp_mat)
        idtp = int(gc.sum() - fn_mat[r, c].sum())
    idfn, idfp = gc.sum() - idtp, tc.sum() - idtp
    return {"IDTP": idtp, "IDF1": idtp / max(1, idtp + 0.5 * idfp + 0.5 * idfn), "IDP": idtp / max(1, idtp + idfp),
            "IDR": idtp / max(1, idtp + idfn)}


def hota(g_frames, t_frames, sims, ng, nt):
    alphas = np.arange(0.05, 0.99, 0.05)
    pot, gc, tc = np.zeros((ng, nt)), np.zeros((ng, 1)), np.zeros((1, nt))
    for g, t, sim in zip(g_frames, t_frames, sims):
        denom = sim.sum(0)[None, :] + sim.sum(1)[:, None] - sim
        s = np.zeros_like(sim)
        m = denom > EPS
        s[m] = sim[m] / denom[m]
        pot[g[:, None], t[None, :]] += s
        gc[g] += 1
        tc[0, t] += 1
    with np.errstate(invalid="ignore", divide="ignore"):
        gas = np.nan_to_num(pot / (gc + tc - pot))
    tp, fn, fp, loc = (np.zeros(len(alphas)) for _ in range(4))
    counts = [np.zeros((ng, nt)) for _ in alphas]
    for g, t, sim in zip(g_frames, t_frames, sims):
        if len(g) == 0 or len(t) == 0:
            fp += len(t)
            fn += len(g)
            continue
        r, c = linear_sum_assignment(-(gas[g[:, None], t[None, :]] * sim))
        for a, alpha in enumerate(alphas):
            ok = sim[r, c] >= alpha - EPS
            tp[a] += ok.sum()
            fn[a] += len(g) - ok.sum()
            fp[a] += len(t) - ok.sum()
            loc[a] += sim[r[ok], c[ok]].sum()
            counts[a][g[r[ok]], t[c[ok]]] += 1
    ass = np.array([np.sum(m * m / np.maximum(1, gc + tc - m)) for m in counts]) / np.maximum(1, tp)
    det = tp / np.maximum(1, tp + fn + fp)
    loca = np.maximum(1e-10, loc) / np.maximum(1e-10, tp)
    return {"HOTA": np.sqrt(det * ass).mean(), "DetA": det.mean(), "AssA": ass.mean(), "LocA": loca.mean()}


def evaluate(gt, tracks):
    g, t, sims, ng, nt = _dense(gt, tracks)
    return {**clear(g, t, sims, ng), **identity(g, t, sims, ng, nt), **hota(g, t, sims, ng, nt)}
