"""Simulated detectors: turn one frame's truth (or its pixels) into boxes with confidences.

``synthetic`` reads the truth (and the label map, where there is one) and fails the way real detectors fail
(``mtt_sim.sim2real.calibrate`` fits it to real detections):
- misses: P(detect) is logistic in the visible fraction, the log of the box height and the target's own ease of
  detection (drawn once), raised for a target detected in the previous frame and lowered after a miss (a two-state
  Markov chain per target), so misses come in runs;
- boxes: the visible extent with per-frame noise and a per-target AR(1) drift of offset and size, true detections
  (IoU >= 0.5 with it); some are outliers (IoU 0.3-0.5), more often after an outlier or a miss; targets whose
  visible regions touch may merge into one box; fragments (always where an occluder cuts a target apart);
- false positives: fresh Poisson clutter and persistent sites, static or held beside a target;
- confidences: Beta draws, their mean for true detections logistic in visibility and height.
With ``memory = false`` every frame is drawn independently at the same rates. ``foreground`` runs background
subtraction, morphology and connected components on the rendered frame, so fragments and merges come from the image.
"""

from __future__ import annotations

import cv2
import numpy as np
from scipy.special import expit, logit

from mtt_sim.boxes import clip_boxes, overlapping_pairs, pair_iou, rows_of, union_boxes
from mtt_sim.core.frame import CLUTTER, UNKNOWN, Detections, Truth
from mtt_sim.core.settings import SensorConfig
from mtt_sim.sim.config import GroupConfig, Scenario

TRUE_BAND = (0.5, 1.01)    # IoU with its target of a true detection's box (its noise is drawn within)
OUTLIER_BAND = (0.3, 0.5)  # IoU with its target of an outlier box: detected, badly (calibrate associates at 0.3)
BESIDE_BAND = (0.1, 0.3)   # IoU with its target of a site held beside it: a false positive, not its detection
_BAND_TRIES = 8
MISSED, GOOD, POOR = 0, 1, 2  # how a target was reported: not at all, with a true box, with an outlier box


def detection_probabilities(visibility: np.ndarray, height: np.ndarray, cfg: SensorConfig,
                            ease: np.ndarray | float = 0.0):
    """(P, P(detect | detected before), P(detect | missed before)) per target.

    logit P = logit(pd) + visibility_slope (visibility - 1) + height_slope log_height + ease (the target's own
    detectability, N(0, pd_spread) drawn once), 0 at or below min_visibility. A two-state chain with lag-1
    correlation miss_corr has P as its long-run share of detected frames: after a detection P + (1 - P) miss_corr,
    after a miss P (1 - miss_corr).
    """
    shift = (cfg.visibility_slope * (visibility - 1) + cfg.height_slope * log_height(height, cfg.reference_height)
             + ease)
    with np.errstate(divide="ignore"):
        p = np.where(visibility > cfg.min_visibility, expit(logit(cfg.pd) + shift), 0.0)
    return p, p + (1 - p) * cfg.miss_corr, p * (1 - cfg.miss_corr)


def log_height(height: np.ndarray, reference: float) -> np.ndarray:
    """min(0, log2(height / reference)): the size covariate of detection and confidence (a detector finds small people
    harder; above the reference height, size no longer helps)."""
    return np.minimum(np.log2(np.maximum(height, 1e-3) / reference), 0.0)


def true_confidence(visibility: np.ndarray, height: np.ndarray, cfg: SensorConfig) -> np.ndarray:
    """Mean confidence (before conf_offset / conf_scale) of a true detection: logit(conf_true) + conf_visibility
    (visibility - 1) + conf_height log_height, through the logistic."""
    return expit(logit(cfg.conf_true) + cfg.conf_visibility * (visibility - 1)
                 + cfg.conf_height * log_height(height, cfg.reference_height))


def touching(labels: np.ndarray, la: int, lb: int, box: np.ndarray) -> bool:
    """Whether a pixel of label `la` is 8-adjacent to one of `lb` inside `box` (x0, y0, x1, y1)."""
    x0, y0, x1, y1 = box
    roi = labels[y0:y1, x0:x1]
    a = cv2.dilate((roi == la).astype(np.uint8), np.ones((3, 3), np.uint8))
    return bool(np.any(a.astype(bool) & (roi == lb)))


def components(n: int, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    """Connected-component index (0..k-1, by smallest member) of n nodes linked by edges (i, j)."""
    label = np.arange(n)
    while len(i):
        low = np.minimum(label[i], label[j])
        if (label[i] == low).all() and (label[j] == low).all():
            break
        np.minimum.at(label, i, low)
        np.minimum.at(label, j, low)
        label = label[label]  # pointer jumping
    return np.unique(label, return_inverse=True)[1]


def _split(box: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
    """A box cut into k fragments along its longer side, with small gaps between them."""
    x, y, w, h = box
    axis = 0 if w >= h else 1
    length = box[2 + axis]
    cuts = np.sort(rng.uniform(0.2, 0.8, k - 1)) * length
    edges = np.concatenate([[0.0], cuts, [length]])
    gap = 0.05 * length
    out = np.repeat(box[None], k, axis=0)
    out[:, axis] = box[axis] + edges[:-1] + np.where(np.arange(k) > 0, gap / 2, 0)
    out[:, 2 + axis] = np.maximum(np.diff(edges) - gap / 2 * ((np.arange(k) > 0) + (np.arange(k) < k - 1)), 0)
    return out  # a fragment squeezed to nothing between close cuts is dropped with the degenerate boxes


def displace(boxes: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Boxes x, y, w, h with their centres moved by offsets[:, :2] and their widths and heights grown by
    offsets[:, 2:], all in units of the box's scale sqrt(w h) (a real detector's pixel errors scale with it, alike
    across and down); a size keeps at least a tenth of what it was."""
    s = np.sqrt(np.prod(boxes[:, 2:], axis=1))[:, None]
    # the centre in the boxes' own dtype (float32 truth boxes), where mtt_sim.boxes.centres casts to float64 first
    c = boxes[:, :2] + boxes[:, 2:] / 2 + offsets[:, :2] * s
    wh = np.maximum(boxes[:, 2:] + offsets[:, 2:] * s, 0.1 * boxes[:, 2:])
    return np.concatenate([c - wh / 2, wh], axis=1)


def offsets_in_band(boxes: np.ndarray, base: np.ndarray, mean: np.ndarray, sigma: np.ndarray, band: tuple[float, float],
                    rng: np.random.Generator, fallback: np.ndarray) -> np.ndarray:
    """Offsets N(mean, sigma) (see `displace`) that move `base` boxes to an IoU in [band) with `boxes`: for each,
    the first of a few draws that does, else its `fallback`."""
    n = len(boxes)
    tries = mean[:, None] + rng.normal(0, 1, (n, _BAND_TRIES, 4)) * sigma
    moved = displace(np.repeat(base, _BAND_TRIES, axis=0), tries.reshape(-1, 4)).reshape(n, _BAND_TRIES, 4)
    iou = pair_iou(boxes[:, None], moved)
    good = (iou >= band[0]) & (iou < band[1])
    return np.where(good.any(axis=1)[:, None], tries[np.arange(n), np.argmax(good, axis=1)], fallback)


def astray(boxes: np.ndarray, spread: float, band: tuple[float, float], rng: np.random.Generator) -> np.ndarray:
    """Offsets of boxes at an IoU in [band) with their own (outliers, sites beside a target): normal with this spread,
    else a sideways shift to the band's middle (by f of the width, a box overlaps itself at IoU (1 - f) / (1 + f))."""
    mid = sum(band) / 2
    sideways = np.zeros((len(boxes), 4))
    sideways[:, 0] = np.where(rng.random(len(boxes)) < 0.5, -1, 1) * (1 - mid) / (1 + mid) * np.sqrt(boxes[:, 2] / boxes[:, 3])
    return offsets_in_band(boxes, boxes, np.zeros((len(boxes), 4)), np.full(4, spread), band, rng, sideways)


class Sensor:
    """What both detector models share: clutter, confidences and the observation limits."""

    def __init__(self, cfg: SensorConfig, image_size: tuple[int, int], nominal: np.ndarray, rng: np.random.Generator):
        """`nominal`: (k, 2) target sizes that clutter takes when nobody is in view."""
        self.cfg, self.rng = cfg, rng
        self.size = tuple(image_size)
        self.nominal = nominal

    def _confidence(self, mean: np.ndarray, false: np.ndarray) -> np.ndarray:
        """Beta draws of the given means (conf_spread, or conf_false_spread for false ones), offset and scaled."""
        cfg = self.cfg
        k = np.where(false & (cfg.conf_false_spread > 0), cfg.conf_false_spread, cfg.conf_spread)
        mean = np.clip(mean, 1e-3, 1 - 1e-3)
        return cfg.conf_offset + cfg.conf_scale * self.rng.beta(mean * k, (1 - mean) * k)

    def random_boxes(self, n: int, truth: Truth) -> np.ndarray:
        """n boxes placed uniformly in the image, sized like the current targets."""
        if not n:
            return np.zeros((0, 4))
        pool = truth.boxes[:, 2:] if len(truth) else self.nominal
        wh = pool[self.rng.integers(len(pool), size=n)] * np.exp(self.rng.normal(0, 0.3, (n, 2)))
        wh = np.minimum(wh, np.array(self.size) * 0.5)
        xy = self.rng.uniform(0, 1, (n, 2)) * (np.array(self.size) - wh)
        return np.concatenate([xy, wh], axis=1)

    def _finish(self, boxes: np.ndarray, mean_conf: np.ndarray, sources: np.ndarray, truth: Truth) -> Detections:
        """Add fresh clutter, draw confidences, clip to the image, drop degenerate boxes, shuffle, keep max_detections."""
        cb = self.random_boxes(self.rng.poisson(self.cfg.clutter_rate), truth)
        boxes = np.concatenate([boxes, cb])
        mean_conf = np.concatenate([mean_conf, np.full(len(cb), self.cfg.conf_false)])
        sources = np.concatenate([sources, np.full(len(cb), CLUTTER)]).astype(np.int64)
        conf = self._confidence(mean_conf, sources == CLUTTER)
        boxes = clip_boxes(boxes, *self.size)
        order = self.rng.permutation(np.flatnonzero((boxes[:, 2] >= 1) & (boxes[:, 3] >= 1)))
        if len(order) > self.cfg.max_detections:  # keep the most confident, in their shuffled order
            order = order[np.sort(np.argsort(-conf[order], kind="stable")[: self.cfg.max_detections])]
        rows = np.empty((len(order), 5), np.float32)
        rows[:, :4], rows[:, 4] = boxes[order], conf[order]
        return Detections(rows, sources[order])


class _Memory:
    """Per target id, from the last frame it was seen: how it was reported (MISSED, GOOD, POOR), its box drift, the
    offsets of its outlier box (kept while it stays poor) and its ease of detection."""

    def __init__(self):
        self.ids, self.state, self.values = np.zeros(0, np.int64), np.zeros(0, np.int8), np.zeros((0, 9))

    def recall(self, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(known, state, drift, outlier offsets, ease) for each id; unknown ids get MISSED and zeros."""
        row = rows_of(self.ids, ids)
        known = row >= 0
        values, state = np.zeros((len(ids), 9)), np.full(len(ids), MISSED, np.int8)
        values[known], state[known] = self.values[row[known]], self.state[row[known]]
        return known, state, values[:, :4], values[:, 4:8], values[:, 8]

    def store(self, ids: np.ndarray, state: np.ndarray, drift: np.ndarray, poor: np.ndarray, ease: np.ndarray) -> None:
        """Keep these targets' outcomes; targets absent from this frame are forgotten."""
        order = np.argsort(ids, kind="stable")
        self.ids, self.state, self.values = ids[order], state[order], np.column_stack([drift, poor, ease])[order]


class _Sites:
    """Persistent false-alarm sites: static background boxes, and boxes held beside a target that move with it."""

    def __init__(self):
        self.owner = np.zeros(0, np.int64)  # target id a site is held beside, or -1 (static)
        self.shape = np.zeros((0, 4))       # static: x, y, w, h; beside a target: offsets in its box sizes

    def fire(self, sensor: SyntheticSensor, truth: Truth) -> np.ndarray:
        """Age, kill and bear sites for this frame; the boxes the living sites report."""
        cfg, rng = sensor.cfg, sensor.rng
        life, rate = (cfg.site_life, cfg.site_rate) if cfg.memory else (1.0, cfg.site_rate * cfg.site_life)
        if not rate and not len(self.owner):
            return np.zeros((0, 4))
        visible = truth.visibility > cfg.min_visibility
        row = rows_of(truth.ids, self.owner)
        keep = (rng.random(len(self.owner)) >= 1 / life) & ((self.owner < 0) | (row >= 0))
        n = rng.poisson(rate)
        beside = (rng.random(n) < cfg.site_near) & visible.any()
        targets = truth.ids[rng.choice(np.flatnonzero(visible), int(beside.sum()))] if beside.any() else []
        owner = np.full(n, -1, np.int64)
        owner[beside] = targets
        shape = np.zeros((n, 4))
        if beside.any():
            shape[beside] = astray(truth.boxes[rows_of(truth.ids, targets)].astype(float), cfg.box_outlier_noise,
                                   BESIDE_BAND, rng)
        shape[~beside] = sensor.random_boxes(int((~beside).sum()), truth)
        self.owner = np.concatenate([self.owner[keep], owner])
        self.shape = np.concatenate([self.shape[keep], shape])
        row = rows_of(truth.ids, self.owner)
        static = self.owner < 0
        shown = static | ((row >= 0) & np.append(visible, False)[row])  # row -1 picks the False
        held = shown & ~static
        out = self.shape[shown].copy()
        out[held[shown]] = displace(truth.boxes[row[held]].astype(float), self.shape[held])
        return out


class SyntheticSensor(Sensor):
    """Detections made from the truth and the label map (no image processing); without a label map (a recorded
    sequence's ground truth) targets whose boxes overlap count as touching."""

    def __init__(self, cfg: SensorConfig, image_size: tuple[int, int], nominal: np.ndarray, rng: np.random.Generator):
        super().__init__(cfg, image_size, nominal, rng)
        self.memory, self.sites = _Memory(), _Sites()

    def detect(self, truth: Truth, labels: np.ndarray | None = None, frame: np.ndarray | None = None) -> Detections:
        cfg, rng = self.cfg, self.rng
        known, last, drift, poor, ease = self.memory.recall(truth.ids)
        if cfg.pd_spread > 0:  # a new target's ease, or (without memory) every target's, drawn afresh
            ease = np.where(known & cfg.memory, ease, rng.normal(0, cfg.pd_spread, len(known)))
        marginal, after_hit, after_miss = detection_probabilities(truth.visibility, truth.boxes[:, 3], cfg, ease)
        pd = np.where(known, np.where(last != MISSED, after_hit, after_miss), marginal) if cfg.memory else marginal
        drift = self._drift(known, drift)
        cand = np.flatnonzero(truth.visibility > cfg.min_visibility)
        obj = self._merge_groups(truth, labels, cand)
        box, p, lead = self._objects(truth, cand, obj, pd)
        found = rng.random(len(lead)) < p
        outlier = found & (rng.random(len(lead)) < self._outlier_probability(last[lead], marginal[lead]))
        hit = found & ~outlier
        if outlier.any():  # a new outlier box, or the same offsets as last frame's
            fresh = astray(box[outlier], cfg.box_outlier_noise, OUTLIER_BAND, rng)
            poor[lead[outlier]] = np.where((cfg.memory & (last[lead[outlier]] == POOR))[:, None], poor[lead[outlier]], fresh)
        state = np.zeros(len(truth), np.int8)
        state[cand] = np.where(hit, GOOD, np.where(outlier, POOR, MISSED))[obj]
        self.memory.store(truth.ids, state, drift, poor, ease)
        boxes, means, rows, kind = self._reports(truth, box, lead, hit, outlier, np.bincount(obj) == 1)
        if cfg.box_noise or cfg.box_size_noise or cfg.box_drift or cfg.box_size_drift or cfg.box_scale != 1 \
                or cfg.box_aspect != 1:
            boxes[kind < 2] = self._noisy(boxes[kind < 2], drift[rows[kind < 2]], whole=kind[kind < 2] == 0)
        if outlier.any():
            boxes[kind == 2] = displace(box[outlier], poor[lead[outlier]])
        false_boxes = self.sites.fire(self, truth)
        false_boxes = displace(false_boxes, self._frame_noise(len(false_boxes), cfg.box_noise, cfg.box_size_noise))
        return self._finish(np.concatenate([boxes, false_boxes]),
                            np.concatenate([means, np.full(len(false_boxes), cfg.conf_false)]),
                            np.concatenate([truth.ids[rows], np.full(len(false_boxes), CLUTTER)]), truth)

    @staticmethod
    def _objects(truth: Truth, cand: np.ndarray, obj: np.ndarray, pd: np.ndarray):
        """Per object (a candidate target, or targets merged into one): its box, P(detect) (its members' largest)
        and the target that names it (the member with the largest visible area)."""
        n_obj = int(obj.max()) + 1 if len(obj) else 0
        if n_obj == len(cand):  # nothing merged: one object per candidate target
            return truth.visible_boxes[cand], pd[cand], cand
        p = np.zeros(n_obj)
        np.maximum.at(p, obj, pd[cand])
        area = np.prod(truth.visible_boxes[cand, 2:], axis=1)
        order = np.lexsort((area, obj))
        return union_boxes(truth.visible_boxes[cand], obj, n_obj), p, cand[order[np.append(np.flatnonzero(np.diff(obj[order])),
                                                                                     len(order) - 1)]]

    def _reports(self, truth: Truth, box: np.ndarray, lead: np.ndarray, hit: np.ndarray, outlier: np.ndarray,
                 single: np.ndarray):
        """The true detections before noise: (boxes, mean confidences, target row of each, kind: 0 whole, 1 piece or
        fragment, 2 outlier).
        A detected target an occluder cuts apart is reported as its pieces, one split with fragment_prob as
        fragments, the rest whole; outliers come last, whole."""
        cfg, rng = self.cfg, self.rng
        mean_of = true_confidence(truth.visibility, truth.boxes[:, 3], cfg)
        mean = mean_of[lead]
        owners = truth.pieces[:, 0].astype(int)
        cut = hit & single & np.isin(lead, owners) if len(owners) else np.zeros(len(lead), bool)
        split = hit & single & ~cut & (rng.random(len(lead)) < cfg.fragment_prob)
        whole = hit & ~cut & ~split
        piece = np.isin(owners, lead[cut]) if len(owners) else np.zeros(0, bool)
        boxes = [box[whole], truth.pieces[piece, 1:]]
        means = [mean[whole], 0.8 * mean_of[owners[piece]]]
        rows = [lead[whole], owners[piece]]
        for o in np.flatnonzero(split):
            parts = _split(box[o], int(rng.integers(2, 4)), rng)
            boxes.append(parts)
            means.append(np.full(len(parts), 0.8 * mean[o]))
            rows.append(np.full(len(parts), lead[o]))
        boxes.append(box[outlier])
        # outliers score lower by conf_outlier (logit); at 0 the means are taken as they are, the draws as before to the bit
        means.append(mean[outlier] if cfg.conf_outlier == 0 else expit(logit(mean[outlier]) + cfg.conf_outlier))
        rows.append(lead[outlier])
        kind = np.repeat([0, 1] + [1] * int(split.sum()) + [2], [len(r) for r in rows])
        return np.concatenate(boxes).astype(float), np.concatenate(means), np.concatenate(rows).astype(int), kind

    def _outlier_probability(self, last: np.ndarray, marginal: np.ndarray) -> np.ndarray:
        """P(a detection's box is an outlier): box_outlier_prob after a good box, box_outlier_persist otherwise.
        Without memory the share the two settle at, x = (P a + b (1 - P)) / (1 + P (a - b)) for P(detect) = P."""
        a, b = self.cfg.box_outlier_prob, self.cfg.box_outlier_persist
        if self.cfg.memory:
            return np.where(last == GOOD, a, b)
        return (marginal * a + b * (1 - marginal)) / (1 + marginal * (a - b))

    def _drift(self, known: np.ndarray, drift: np.ndarray) -> np.ndarray:
        """This frame's per-target box drift: AR(1) from the last for known targets, stationary for new ones."""
        cfg = self.cfg
        if not cfg.memory or cfg.box_drift == cfg.box_size_drift == 0:
            return np.zeros((len(known), 4))
        rho = cfg.box_drift_corr
        fresh = self.rng.normal(0, 1, (len(known), 4)) * np.array([cfg.box_drift] * 2 + [cfg.box_size_drift] * 2)
        return np.where(known[:, None], rho * drift + np.sqrt(1 - rho**2) * fresh, fresh)

    def _noisy(self, boxes: np.ndarray, drift: np.ndarray, whole: np.ndarray) -> np.ndarray:
        """True boxes scaled by box_scale and box_aspect about their centres, with their target's drift and per-frame
        noise; the noise of a whole box is drawn to keep it a true detection (IoU >= 0.5 with the box; where a few
        draws miss that, the scaled box alone: a drift that strays too far is a poor box, which outliers model).
        Without memory the drift's variance joins the per-frame noise."""
        cfg = self.cfg
        centre, size = cfg.box_noise, cfg.box_size_noise
        if not cfg.memory:
            centre, size = np.hypot(centre, cfg.box_drift), np.hypot(size, cfg.box_size_drift)
        root = np.sqrt(cfg.box_aspect)
        wh = boxes[:, 2:] * cfg.box_scale * np.array([root, 1 / root])
        scaled = np.concatenate([boxes[:, :2] + (boxes[:, 2:] - wh) / 2, wh], axis=1)
        offsets = drift + self._frame_noise(len(boxes), centre, size)
        if whole.any():
            offsets[whole] = offsets_in_band(boxes[whole], scaled[whole], drift[whole],
                                             np.array([centre, centre, size, size]), TRUE_BAND, self.rng,
                                             np.zeros_like(drift[whole]))
        return displace(scaled, offsets)

    def _frame_noise(self, n: int, centre: float, size: float) -> np.ndarray:
        """Per-frame offsets (see `displace`): normal, centre noise across and down, size noise in width and height."""
        return self.rng.normal(0, 1, (n, 4)) * np.array([centre, centre, size, size])

    def _merge_groups(self, truth: Truth, labels: np.ndarray | None, cand: np.ndarray) -> np.ndarray:
        """Object index of each candidate: targets whose visible regions touch are linked with merge_prob."""
        n = len(cand)
        if n < 2 or self.cfg.merge_prob <= 0:
            return np.arange(n)
        vb = truth.visible_boxes[cand]
        i, j = overlapping_pairs(vb, margin=1.0 if labels is not None else 0.0)
        linked = self.rng.random(len(i)) < self.cfg.merge_prob
        i, j = i[linked], j[linked]
        if not len(i) or labels is None:
            return components(n, i, j)
        h, w = labels.shape
        lo, hi = vb[:, :2], vb[:, :2] + vb[:, 2:]
        ok = np.zeros(len(i), bool)
        for e, (a, b) in enumerate(zip(i.tolist(), j.tolist())):
            x0, y0 = np.maximum(np.minimum(lo[a], lo[b]) - 1, 0).astype(int)
            x1, y1 = np.minimum(np.maximum(hi[a], hi[b]) + 1, (w, h)).astype(int)
            ok[e] = touching(labels, int(truth.labels[cand[a]]), int(truth.labels[cand[b]]), (x0, y0, x1, y1))
        return components(n, i[ok], j[ok])


class ForegroundSensor(Sensor):
    """Background subtraction against a running background model, morphology and connected components."""

    def __init__(self, cfg: SensorConfig, image_size: tuple[int, int], nominal: np.ndarray, rng: np.random.Generator,
                 background: np.ndarray):
        super().__init__(cfg, image_size, nominal, rng)
        self.model = cv2.cvtColor(background, cv2.COLOR_RGB2GRAY).astype(np.float32)
        self.open = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
        self.close = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5))

    def detect(self, truth: Truth, labels: np.ndarray, frame: np.ndarray | None = None) -> Detections:
        if frame is None:
            raise ValueError("the foreground sensor needs the rendered frame")
        cfg = self.cfg
        gray = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY)
        diff = cv2.absdiff(gray, cv2.convertScaleAbs(self.model))
        mask = cv2.threshold(diff, cfg.threshold, 1, cv2.THRESH_BINARY)[1]  # diff > threshold (diff is integer)
        mask = cv2.morphologyEx(cv2.morphologyEx(mask, cv2.MORPH_OPEN, self.open), cv2.MORPH_CLOSE, self.close)
        count, comp = cv2.connectedComponentsWithAlgorithm(mask, 8, cv2.CV_32S, cv2.CCL_GRANA)
        cv2.accumulateWeighted(gray, self.model, cfg.learning_rate, mask=1 - mask)
        area, boxes, summed = component_stats(comp, count, mask, diff)
        keep = np.flatnonzero(area >= max(cfg.min_area, 1))
        contrast = summed[keep] / area[keep]
        # confidence: strong contrast and a target-sized area make a blob believable
        mean = np.clip(contrast / (4 * cfg.threshold), 0, 1) * (1 - np.exp(-area[keep] / (5 * max(cfg.min_area, 1))))
        return self._finish(boxes[keep], mean, np.full(len(keep), UNKNOWN), truth)


def component_stats(comp: np.ndarray, count: int, mask: np.ndarray, weights: np.ndarray):
    """Area, box x, y, w, h and summed `weights` of components 1..count-1 of label image `comp` (nonzero where `mask`
    is), as floats. Read from the foreground pixels alone: cv2's own stats pass scans the whole image (about 1 ms
    of a soccer step at 720x576, where the labelling itself takes 0.4 ms)."""
    xy = cv2.findNonZero(mask)
    xy = np.zeros((0, 2), np.int32) if xy is None else xy.reshape(-1, 2)
    x, y = xy[:, 0], xy[:, 1]
    which = comp[y, x] - 1
    area = np.bincount(which, minlength=count - 1).astype(float)
    boxes = union_boxes(np.concatenate([xy, np.ones_like(xy)], axis=1).astype(float), which, count - 1)
    return area, boxes, np.bincount(which, weights=weights[y, x], minlength=count - 1)


def make_sensor(sc: Scenario, rng: np.random.Generator, background: np.ndarray | None) -> Sensor:
    """The scenario's detector; `background` (an empty frame, needed by the foreground model only) seeds the
    foreground model."""
    parts = (sc.sensor, (sc.render.width, sc.render.height), np.array([g.size for g in sc.groups], float), rng)
    if sc.sensor.model == "foreground":
        return ForegroundSensor(*parts, background)
    return SyntheticSensor(*parts)


def twin_sensor(cfg: SensorConfig, image_size: tuple[int, int], rng: np.random.Generator) -> SyntheticSensor:
    """The synthetic detector on a recorded sequence's people (its twin); clutter takes the size of a default target
    when nobody is in view."""
    return SyntheticSensor(cfg, image_size, np.array([GroupConfig().size], float), rng)
