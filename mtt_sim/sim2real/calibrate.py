"""Fit the synthetic detector to real detections, and measure how a detector fails: `mtt-sim calibrate`.

Each frame's detections are associated with its people (the sequence's ground truth, every person row, scored or
not: a real detector fires on them all) by the Hungarian method, first at IoU >= 0.5 (true detections), then the
rest at IoU >= 0.3 (outliers: the person was detected, with a poor box); what is left is a false positive.
The fit, per part of the model (`mtt_sim.sim.sensor`):
- misses: maximum likelihood (L-BFGS) of the two-state chain of detections with logistic covariates and a
  per-person random ease of detection over every person-frame (a person seen in the previous frame continues its
  chain, a new one starts at its long-run P), then the intercept matched to the data's share of detected frames;
  outliers: their share of the detections after a true one, and after anything else;
- boxes: matched moments of the true detections' residuals (offset in box sizes, log size ratio): mean log size is
  box_scale; variance, lag-1 and lag-2 covariance of a person's residuals give the AR(1) drift and the per-frame
  noise, then the per-frame noise matched to how much the detections jump from frame to frame (`fit_jitter`: the
  annotators' jitter is not the detector's); outliers' share and spread;
- false positives: linked frame to frame (IoU >= 0.5) into runs; the number of runs per frame, their mean length
  and the share of one-frame runs give fresh clutter, the site birth rate and the site life (matched moments);
  the share of runs that overlap a person (IoU >= 0.1) is site_near;
- merges and fragments: counted (a false positive covering two overlapping people; several inside a missed one);
- confidences: offset and scale from their range; the good boxes' mean confidence (logistic in visibility and
  height) and Beta concentration by maximum likelihood, the outliers' lower mean by maximum likelihood, the false
  positives' Beta by moments.
`statistics` measures the same things on any detections of a ground truth, so the twin is checked against the data
with one function.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np
from scipy.optimize import brentq, minimize
from scipy.special import expit, logit, logsumexp

from mtt_sim.boxes import box_iou, match, overlap, overlapping_pairs, union_boxes
from mtt_sim.core.frame import Truth
from mtt_sim.real.sequence import Recording, SequenceConfig
from mtt_sim.sim import scenario as scn
from mtt_sim.sim.sensor import log_height, twin_sensor
from mtt_sim.sim2real import fit_confidences, fit_jitter, truth_statistics

MATCH_IOU = 0.5     # a true detection
OUTLIER_IOU = 0.3   # a detection of the person with a poor box
NEAR_IOU = 0.1      # a false positive beside a person
RUN_BINS = (1, 2, 3, 6, 11, 31)  # run-length histogram bins: 1, 2, 3-5, 6-10, 11-30, 31+
VISIBILITY_BINS = (0.0, 0.25, 0.5, 0.75, 1.0001)
HEIGHT_BINS = (0, 50, 100, 200, 1e9)


@dataclass(frozen=True)
class Associated:
    """Detections associated with the people of a sequence: one row per person-frame and one per detection."""

    frame: np.ndarray       # person-frames: frame index
    ident: np.ndarray       # person id
    visibility: np.ndarray
    height: np.ndarray      # box height, px
    hit: np.ndarray         # detected at IoU >= MATCH_IOU
    detected: np.ndarray    # detected at all (hit, or an outlier at IoU >= OUTLIER_IOU)
    iou: np.ndarray         # IoU of its detection (nan if none)
    box: np.ndarray         # (n, 4) its box
    match: np.ndarray       # (n, 4) its detection's box (nan if none)
    conf: np.ndarray        # confidence of its detection (nan if none)
    det_frame: np.ndarray   # detections: frame index
    det_box: np.ndarray     # (m, 4)
    det_conf: np.ndarray
    det_kind: np.ndarray    # 0 true, 1 outlier, 2 false positive
    det_near: np.ndarray    # overlaps a person with IoU >= NEAR_IOU
    merged: int             # false positives that cover two overlapping people
    pairs: int              # pairs of people whose boxes overlap (person-frames)
    fragmented: int         # missed person-frames with two or more false positives inside the box
    frames: int


def associate(truths: Sequence[Truth], detections: Sequence[np.ndarray]) -> Associated:
    """Associate each frame's detections (n, 5) with its people (see the module docstring)."""
    people, dets = [], []
    merged = pairs = fragmented = 0
    for k, (t, d) in enumerate(zip(truths, detections)):
        d = np.asarray(d, float)
        sim = box_iou(t.boxes, d[:, :4]) if len(t) and len(d) else np.zeros((len(t), len(d)))
        r1, c1 = match(sim, MATCH_IOU)
        free_t, free_d = np.setdiff1d(np.arange(len(t)), r1), np.setdiff1d(np.arange(len(d)), c1)
        r2, c2 = match(sim[np.ix_(free_t, free_d)], OUTLIER_IOU)
        r2, c2 = free_t[r2], free_d[c2]
        det_of = np.full(len(t), -1)
        det_of[r1], det_of[r2] = c1, c2
        kind = np.full(len(d), 2)
        kind[c1], kind[c2] = 0, 1
        boxes, j = t.boxes.astype(float), np.maximum(det_of, 0)
        found = det_of >= 0
        det_row = np.full((len(t), 5), np.nan)
        if len(d):
            det_row[found] = d[j[found], :5]
        people.append(np.c_[np.full(len(t), k), t.ids, t.visibility, boxes[:, 3], np.isin(np.arange(len(t)), r1),
                            found, np.where(found, sim[np.arange(len(t)), j] if len(d) else 0, np.nan), boxes, det_row])
        near = sim.max(axis=0) >= NEAR_IOU if len(t) else np.zeros(len(d), bool)
        dets.append(np.c_[np.full(len(d), k), d[:, :5], kind, near])
        if len(t) > 1:
            i, jj = overlapping_pairs(boxes)
            pairs += len(i)
            false = d[kind == 2, :4]
            if len(i) and len(false):
                pair = np.arange(len(i))
                cover = box_iou(union_boxes(boxes[np.r_[i, jj]], np.r_[pair, pair], len(i)), false) >= MATCH_IOU
                alone = (sim[i][:, kind == 2] < MATCH_IOU) & (sim[jj][:, kind == 2] < MATCH_IOU)
                merged += int((cover & alone).any(axis=1).sum())
        if len(d) and (~found).any():
            inside = _inside(boxes[~found], d[kind == 2, :4])
            fragmented += int((inside.sum(axis=1) >= 2).sum())
    p = np.concatenate(people) if people else np.zeros((0, 16))
    q = np.concatenate(dets) if dets else np.zeros((0, 8))
    return Associated(frame=p[:, 0].astype(int), ident=p[:, 1].astype(np.int64), visibility=p[:, 2], height=p[:, 3],
                      hit=p[:, 4] > 0, detected=p[:, 5] > 0, iou=p[:, 6], box=p[:, 7:11], match=p[:, 11:15], conf=p[:, 15],
                      det_frame=q[:, 0].astype(int), det_box=q[:, 1:5], det_conf=q[:, 5], det_kind=q[:, 6].astype(int),
                      det_near=q[:, 7] > 0, merged=merged, pairs=pairs, fragmented=fragmented, frames=len(truths))


def _inside(boxes: np.ndarray, dets: np.ndarray) -> np.ndarray:
    """(people, detections): whether at least 80 % of a detection's area lies in a person's box."""
    inter, _, area = overlap(boxes[:, None], dets[None])
    return inter >= 0.8 * area


# ------------------------------------------------------------------ sequences of person-frames and of false positives

def _chains(a: Associated) -> tuple[np.ndarray, np.ndarray]:
    """Person-frames sorted by person and frame, and whether each continues the previous row (same person, next frame)."""
    order = np.lexsort((a.frame, a.ident))
    cont = np.zeros(len(order), bool)
    cont[1:] = (a.ident[order][1:] == a.ident[order][:-1]) & (a.frame[order][1:] == a.frame[order][:-1] + 1)
    return order, cont


def _jitter(a: Associated) -> tuple[float, float]:
    """`fit_jitter.jitter` of the true detections: how much their boxes jump from frame to frame."""
    order, cont = _chains(a)
    return fit_jitter.jitter(a.hit[order], a.match[order], cont)


def run_lengths(values: np.ndarray, cont: np.ndarray) -> np.ndarray:
    """Lengths of the runs of True in `values`, a run broken where `cont` is False."""
    start = values & ~np.r_[False, values[:-1] & cont[1:]] if len(values) else values
    run = np.cumsum(start) - 1
    return np.bincount(run[values], minlength=int(start.sum())) if values.any() else np.zeros(0, int)


def false_runs(a: Associated, kinds: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """False positives of these kinds linked frame to frame (IoU >= 0.5, Hungarian): (run lengths, whether each run
    starts beside a person)."""
    keep = np.isin(a.det_kind, kinds)
    frames, boxes, near = a.det_frame[keep], a.det_box[keep], a.det_near[keep]
    bounds = np.searchsorted(frames, np.arange(a.frames + 1))
    lengths, starts_near = [], []
    alive_box, alive_len, alive_near = np.zeros((0, 4)), np.zeros(0, int), np.zeros(0, bool)
    for k in range(a.frames + 1):
        b = boxes[bounds[k]: bounds[k + 1]] if k < a.frames else np.zeros((0, 4))
        nb = near[bounds[k]: bounds[k + 1]] if k < a.frames else np.zeros(0, bool)
        r, c = match(box_iou(alive_box, b) if len(alive_box) and len(b) else np.zeros((len(alive_box), len(b))),
                      MATCH_IOU)
        ended = np.setdiff1d(np.arange(len(alive_box)), r)
        lengths += alive_len[ended].tolist()
        starts_near += alive_near[ended].tolist()
        new = np.setdiff1d(np.arange(len(b)), c)
        alive_box = np.concatenate([b[c], b[new]])
        alive_len = np.concatenate([alive_len[r] + 1, np.ones(len(new), int)])
        alive_near = np.concatenate([alive_near[r], nb[new]])
    return np.array(lengths, int), np.array(starts_near, bool)


# ------------------------------------------------------------------ the fit

def fit(a: Associated) -> dict:
    """The synthetic detector's keys fitted to associated detections (see the module docstring)."""
    if not a.detected.any():
        raise ValueError("no detection of a person to fit to (does the sequence have det/det.txt and gt/gt.txt?)")
    out = {"model": "synthetic", "memory": True}
    out.update(_fit_misses(a))
    out.update(_fit_boxes(a))
    out.update(_fit_false_positives(a))
    out.update(fit_confidences.fit(a, out["reference_height"]))
    out["merge_prob"] = a.merged / a.pairs if a.pairs else 0.0
    out["fragment_prob"] = a.fragmented / len(a.frame)
    return {k: (round(float(v), 4) if isinstance(v, (float, np.floating)) else v) for k, v in out.items()}


def _fit_misses(a: Associated) -> dict:
    """Maximum likelihood (L-BFGS) of the chain of detections (true or outlier): P = expit(b0 + b1 (v - 1) + b2
    min(0, log2(h / ref)) + u) with lag-1 correlation miss_corr, over person-frames above min_visibility (the 1st
    percentile of the detected ones' visibility); u ~ N(0, pd_spread) is each person's own ease of detection, drawn
    once per stretch of frames it is present (integrated out by Gauss-Hermite quadrature). The knee ref is the best of
    the height deciles without u. Outliers: their share of the detections after a true one, and after an outlier, a
    miss or nothing."""
    min_visibility = max(0.0, float(np.quantile(a.visibility[a.detected], 0.01)) - 0.01)
    order, cont = _chains(a)
    use = a.visibility[order] > min_visibility
    y = a.detected[order][use]
    prev = np.where(cont, np.r_[False, a.detected[order][:-1]], -1)[use]  # -1: the first frame of a person's chain
    v, h = a.visibility[order][use] - 1, a.height[order][use]
    stretch = (np.cumsum(~cont) - 1)[use]
    starts = np.flatnonzero(np.r_[True, stretch[1:] != stretch[:-1]])
    nodes, weights = np.polynomial.hermite_e.hermegauss(15)  # for a standard normal u
    weights = weights / weights.sum()

    def log_q(theta, x, u):
        """log P(the observed outcome) per row (and per value of u)."""
        p = expit((x @ theta[:3])[:, None] + u)
        lam = expit(theta[3])
        q = np.where((prev == 1)[:, None], p + (1 - p) * lam, np.where((prev == 0)[:, None], p * (1 - lam), p))
        q = np.clip(q, 1e-12, 1 - 1e-12)
        return np.where(y[:, None], np.log(q), np.log1p(-q))

    def nll_fixed(theta, x):
        return -log_q(theta, x, np.zeros(1)).sum()

    def nll(theta, x):
        per_stretch = np.add.reduceat(log_q(theta, x, np.exp(theta[4]) * nodes), starts, axis=0)
        return -logsumexp(per_stretch, b=weights, axis=1).sum()

    best = None
    start = np.array([logit(np.clip(y.mean(), 0.01, 0.99)), 2.0, 1.0, 0.0])
    for knee in np.unique(np.round(np.quantile(h, np.linspace(0.1, 0.9, 9)))):
        x = np.c_[np.ones(len(y)), v, log_height(h, knee)]
        res = minimize(nll_fixed, start, args=(x,), method="L-BFGS-B")
        if best is None or res.fun < best[0]:
            best = (res.fun, res.x, knee, x)
    _, theta, knee, x = best
    theta = minimize(nll, np.r_[theta, math.log(0.5)], args=(x,), method="L-BFGS-B",
                     bounds=[(None, None)] * 4 + [(math.log(1e-3), math.log(10.0))]).x
    def detected_share(b0):
        """The model's mean P(detect) over the rows with intercept b0, u integrated out."""
        return float(np.mean(expit((x[:, 1:] @ theta[1:3] + b0)[:, None] + np.exp(theta[4]) * nodes) @ weights))

    # the chain's share of detected frames follows P only on average: match the intercept to the data's share
    theta[0] = brentq(lambda b0: detected_share(b0) - y.mean(), theta[0] - 10, theta[0] + 10)
    detected, poor = a.detected[order], (a.detected & ~a.hit)[order]
    after_good = np.r_[False, a.hit[order][:-1]] & cont
    return {"pd": expit(theta[0]), "pd_spread": math.exp(theta[4]), "miss_corr": min(expit(theta[3]), 0.999),
            "visibility_slope": float(np.clip(theta[1], 0, 100)), "height_slope": float(np.clip(theta[2], -10, 10)),
            "reference_height": float(knee), "min_visibility": min_visibility,
            "box_outlier_prob": float(poor[detected & after_good].mean()) if (detected & after_good).any() else 0.0,
            "box_outlier_persist": float(poor[detected & ~after_good].mean()) if (detected & ~after_good).any() else 0.0}


def _fit_boxes(a: Associated) -> dict:
    """Moments of the true detections' boxes: scale and aspect from the mean log size ratios; the residuals about
    the scaled box, in units of its sqrt(w h): their second moments, lag-1 and lag-2 covariances of a person's
    residuals give the AR(1) drift (of the centre and of the size, one correlation) and the per-frame noise;
    outliers."""
    order, cont = _chains(a)
    hit, box, match = a.hit[order], a.box[order], a.match[order]
    ratio = np.log(match[hit, 2:] / box[hit, 2:])
    scale, aspect = np.exp(ratio.mean()), np.exp(np.mean(ratio[:, 0] - ratio[:, 1]))
    wh = box[:, 2:] * scale * np.array([np.sqrt(aspect), 1 / np.sqrt(aspect)])
    unit = np.sqrt(np.prod(wh, axis=1))[:, None]
    e = np.c_[match[:, :2] + match[:, 2:] / 2 - box[:, :2] - box[:, 2:] / 2, match[:, 2:] - wh] / unit
    (centre, c1, c2), (size, s1, s2) = _lagged(e[:, :2], hit, cont), _lagged(e[:, 2:], hit, cont)
    # an AR(1) drift of variance D plus white noise has lag-k covariance D rho^k; one rho for centre and size
    rho = float(np.clip((c2 + s2) / (c1 + s1), 0.0, 0.999)) if c1 + s1 > 0 else 0.9
    drift, size_drift = (min(c1 / rho, centre), min(s1 / rho, size)) if rho > 0 and min(c1, s1) > 0 else (0.0, 0.0)
    outlier = a.detected & ~a.hit
    spread = a.match[outlier, :4] - a.box[outlier]  # about the true box, as outliers are drawn
    spread[:, :2] += (spread[:, 2:]) / 2
    spread /= np.sqrt(np.prod(a.box[outlier, 2:], axis=1))[:, None]
    return {"box_noise": math.sqrt(centre - drift), "box_size_noise": math.sqrt(size - size_drift),
            "box_drift": math.sqrt(drift), "box_size_drift": math.sqrt(size_drift), "box_drift_corr": rho,
            "box_scale": float(np.clip(scale, 0.5, 2.0)), "box_aspect": float(np.clip(aspect, 0.25, 4.0)),
            "box_outlier_noise": float(np.clip(np.sqrt(np.mean(spread ** 2)), 0.01, 2)) if outlier.any() else 0.3}


def _lagged(e: np.ndarray, hit: np.ndarray, cont: np.ndarray) -> tuple[float, float, float]:
    """Variance and lag-1, lag-2 covariances of the residuals e (rows in chain order) over true detections."""
    lag1 = cont[1:] & hit[1:] & hit[:-1]
    lag2 = cont[2:] & cont[1:-1] & hit[2:] & hit[:-2]
    cov = lambda k, sel: float(np.mean(e[k:][sel] * e[:-k][sel])) if sel.any() else 0.0  # noqa: E731
    return float(np.mean(e[hit] ** 2)), cov(1, lag1), cov(2, lag2)


def _fit_false_positives(a: Associated) -> dict:
    """Fresh clutter c, sites born at s per frame living L frames (geometric): runs per frame R = c + s, mean run
    m = (c + s L) / R, share of one-frame runs f1 = (c + s / L) / R, solved for c, s, L."""
    lengths, near = false_runs(a, (2,))
    if not len(lengths):
        return {"clutter_rate": 0.0, "site_rate": 0.0, "site_life": 10.0, "site_near": 0.5}
    rate, m, f1 = len(lengths) / a.frames, lengths.mean(), float(np.mean(lengths == 1))
    life = (m - 1) / (1 - f1) if f1 < 1 else 1.0
    if life <= 1:
        clutter, sites, life = rate, 0.0, 10.0
    else:
        sites = rate * (m - 1) / (life - 1)
        clutter = rate - sites
        if clutter < 0:
            clutter, sites, life = 0.0, rate, m
    lasting = lengths > 1
    return {"clutter_rate": clutter, "site_rate": sites, "site_life": max(life, 1.0),
            "site_near": float(near[lasting].mean() if lasting.any() else near.mean())}


# ------------------------------------------------------------------ statistics, on the data and on the twin

def statistics(a: Associated) -> dict:
    """How a detector fails on a ground truth, at IoU >= 0.5: misses and their runs, recall by visibility and height,
    false positives and their persistence, box overlap, confidences."""
    order, cont = _chains(a)
    miss = ~a.hit[order]
    after_miss = cont[1:] & miss[:-1]
    misses, hits = run_lengths(miss, cont), run_lengths(~miss, cont)
    lengths, _ = false_runs(a, (1, 2))
    true, false = a.hit, a.det_kind != 0
    out = {"P(miss)": miss.mean(), "P(miss | miss)": miss[1:][after_miss].mean() if after_miss.any() else math.nan,
           "mean miss run": misses.mean() if len(misses) else math.nan,
           "mean hit run": hits.mean() if len(hits) else math.nan}
    for name, runs in (("miss runs", misses), ("hit runs", hits)):
        counts = np.histogram(runs, bins=(*RUN_BINS, np.inf))[0]
        for lo, hi, c in zip(RUN_BINS, (*RUN_BINS[1:], None), counts):
            label = f"{lo}" if hi == lo + 1 else (f"{lo}-{hi - 1}" if hi else f"{lo}+")
            out[f"{name} {label} (share)"] = c / max(len(runs), 1)
    for name, values, bins in (("visibility", a.visibility, VISIBILITY_BINS), ("height px", a.height, HEIGHT_BINS)):
        which = np.digitize(values, bins[1:-1])
        for b in range(len(bins) - 1):
            label = f"{bins[b]:g}-{bins[b + 1]:g}" if b < len(bins) - 2 else f"{bins[b]:g}+"
            sel = which == b
            out[f"recall, {name} {label}"] = a.hit[sel].mean() if sel.any() else math.nan
    out.update({"false positives per frame": false.sum() / max(a.frames, 1),
                "mean false-positive run": lengths.mean() if len(lengths) else math.nan,
                "false positives in runs > 1 (share)": lengths[lengths > 1].sum() / max(lengths.sum(), 1),
                "false positives beside a person (share)": a.det_near[false].mean() if false.any() else math.nan,
                "mean IoU of true detections": np.nanmean(a.iou[true]) if true.any() else math.nan,
                **dict(zip(fit_jitter.NAMES, _jitter(a))),
                "average precision": average_precision(a.det_conf, a.det_kind == 0, len(a.frame)),
                "precision, lowest fifth of confidences": _low_precision(a.det_conf, a.det_kind == 0),
                "confidence, true (mean)": np.nanmean(a.conf[true]) if true.any() else math.nan,
                "confidence, true (std)": np.nanstd(a.conf[true]) if true.any() else math.nan,
                "confidence, false (mean)": a.det_conf[false].mean() if false.any() else math.nan,
                "confidence, false (std)": a.det_conf[false].std() if false.any() else math.nan})
    return {k: float(v) for k, v in out.items()}


def _low_precision(conf: np.ndarray, true: np.ndarray, share: float = 0.2) -> float:
    """The share of true detections among the `share` of the detections with the lowest confidences: what a tracker's
    confidence threshold drops."""
    if not len(conf):
        return math.nan
    return float(true[conf <= np.quantile(conf, share)].mean())


def average_precision(conf: np.ndarray, true: np.ndarray, positives: int) -> float:
    """Area under the precision-recall curve of detections ranked by confidence, precision made monotone (all-point
    interpolation, as PASCAL VOC and MOTChallenge's detection benchmark); `positives`: the people to find."""
    if not positives:
        return math.nan
    order = np.argsort(-conf, kind="stable")
    tp = np.cumsum(true[order])
    recall, precision = tp / positives, tp / np.arange(1, len(order) + 1)
    precision = np.maximum.accumulate(precision[::-1])[::-1]
    return float(np.sum(np.diff(np.r_[0.0, recall]) * precision))


@dataclass(frozen=True)
class Source:
    """One sequence read for calibration: its recording, its people frame by frame and its detections associated."""

    recording: Recording
    truths: list
    associated: Associated


def read(folder: str | Path) -> Source:
    """A sequence folder with gt/gt.txt and det/det.txt, associated."""
    rec = Recording(folder)
    if not rec.scored or not (Path(folder) / "det" / "det.txt").is_file():
        raise scn.ConfigError(f"{folder}: calibrating needs both gt/gt.txt and det/det.txt")
    truths = [rec.truth(k) for k in range(len(rec))]
    associated = associate(truths, [rec.detections(k) for k in range(len(rec))])
    if not associated.detected.any():
        raise scn.ConfigError(f"{folder}: no detection of a person to fit to (none of the {rec.detection_rows} rows of "
                              "det/det.txt overlaps a person of gt/gt.txt)")
    return Source(rec, truths, associated)


def twin_detections(source: Source, sensor: dict, seed: int) -> list[np.ndarray]:
    """What the synthetic detector with these keys reports on the sequence's people, frame by frame."""
    rec = source.recording
    cfg = scn.from_mapping({"sensor": {**sensor, "model": "synthetic"}}, str(rec.folder), SequenceConfig).sensor
    s = twin_sensor(cfg, rec.image_size, np.random.default_rng(seed))
    return [s.detect(t).rows.astype(float) for t in source.truths]


def scenario_statistics(scenario: str, config: dict | None = None, seeds: Sequence[int] = (0,),
                        steps: int | None = None) -> dict:
    """`statistics` of a scenario's detector on its own targets (every target, hidden ones too), episodes pooled:
    what a preset does on a scene, e.g. its average precision."""
    truths, detections = [], []
    for seed in seeds:
        t, d = truth_statistics.record(scenario, config, seed, steps)
        truths += t
        detections += d
    return statistics(associate(truths, detections))


def twin_statistics(sources: Sequence[Source], sensor: dict, seeds: int, bar=None) -> dict:
    """`statistics` of the twin's detections on these sequences, the mean over `seeds` runs (`bar`: a progress bar
    to move on a run at a time)."""
    runs = []
    for seed in range(seeds):
        if bar is not None:
            bar.set_description(f"twin run {seed + 1} of {seeds}")
        runs.append(statistics(pooled([associate(src.truths, twin_detections(src, sensor, seed)) for src in sources])))
        if bar is not None:
            bar.update()
    with np.errstate(invalid="ignore"):
        return {k: float(np.mean([r[k] for r in runs])) for k in runs[0]}


@dataclass(frozen=True)
class Calibration:
    """A fit and the statistics it was checked with."""

    sensor: dict
    data: dict
    twin: dict
    sources: tuple[str, ...]
    person_frames: int
    detections: int


def calibrate(folders: Sequence[str | Path], seeds: int = 3, progress: bool = False) -> Calibration:
    """Fit the detector on every folder's detections together, and check it: the twin's statistics are the mean over
    `seeds` runs of the fitted detector on the same people. `progress`: a bar on stderr over the folders read, the fit
    and the twin runs."""
    from tqdm import tqdm

    with tqdm(total=len(folders) + 1 + seeds, unit="step", leave=False, disable=not progress, delay=1.0) as bar:
        sources = []
        for f in folders:
            bar.set_description(f"reading {Path(f).name}")
            sources.append(read(f))
            bar.update()
        together = pooled([src.associated for src in sources])
        bar.set_description("fitting the detector")
        try:
            sensor = fitted(sources)
        except (ValueError, RuntimeError) as err:  # too few or too alike detections for a fit: say whose
            raise ValueError(f"{', '.join(map(str, folders))}: the detector cannot be fitted to these detections "
                             f"({err})") from None
        bar.update()
        twin = twin_statistics(sources, sensor, seeds, bar)
    return Calibration(sensor, statistics(together), twin, tuple(str(f) for f in folders), len(together.frame),
                       len(together.det_frame))


def fitted(sources: Sequence[Source]) -> dict:
    """The detector fitted to these sequences' detections together: `fit`, then its per-frame box noise matched to
    how much the detections jump from frame to frame (`fit_jitter`, the twin run on the same people)."""
    together = pooled([src.associated for src in sources])
    return fit_jitter.match_noise(fit(together), _jitter(together), lambda keys: _jitter(
        pooled([associate(src.truths, twin_detections(src, keys, 0)) for src in sources])))


def pooled(parts: Sequence[Associated]) -> Associated:
    """Several sequences' associations as one (frame numbers offset so that no chain or run crosses sequences)."""
    if len(parts) == 1:
        return parts[0]
    offsets = np.cumsum([0] + [p.frames + 1 for p in parts[:-1]])
    cat = lambda name: np.concatenate([getattr(p, name) for p in parts])  # noqa: E731
    return Associated(**{name: cat(name) for name in ("ident", "visibility", "height", "hit", "detected", "iou",
                                                      "box", "match", "conf", "det_box", "det_conf", "det_kind", "det_near")},
                      frame=np.concatenate([p.frame + o for p, o in zip(parts, offsets)]),
                      det_frame=np.concatenate([p.det_frame + o for p, o in zip(parts, offsets)]),
                      merged=sum(p.merged for p in parts), pairs=sum(p.pairs for p in parts),
                      fragmented=sum(p.fragmented for p in parts), frames=int(offsets[-1] + parts[-1].frames))


def report(c: Calibration) -> str:
    """The data's statistics beside the fitted twin's, as a text table."""
    width = max(map(len, c.data))
    lines = [f"{'statistic':{width}s}  {'data':>8s}  {'twin':>8s}"]
    lines += [f"{k:{width}s}  {c.data[k]:8.3f}  {c.twin[k]:8.3f}" for k in c.data]
    return "\n".join(lines)


def to_toml(c: Calibration) -> str:
    """The fitted [sensor] table, with a header saying what it was fitted to and how."""
    return sensor_toml(c.sensor, [
        f"mtt-sim calibrate: the synthetic detector fitted to {', '.join(Path(s).name for s in c.sources)}",
        f"({c.person_frames} person-frames, {c.detections} detections). Misses: maximum likelihood; boxes, false",
        "positives and confidences: matched moments (see mtt_sim/sim2real/calibrate.py)."])


def sensor_toml(sensor: dict, comments: Sequence[str] = ()) -> str:
    """A [sensor] table as TOML text (what read_sensor and the presets read), numbers as floats, after a comment of
    these lines."""
    table = {k: v if isinstance(v, (bool, str)) else float(v) for k, v in sensor.items()}
    return scn.to_toml({"sensor": table}, comments)
