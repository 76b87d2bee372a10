"""Simulated detectors: turn one frame's truth (or its pixels) into boxes with confidences.

``synthetic`` reads the label map: each visible target is detected with a probability that rises
with its visible fraction, reported as its visible extent plus noise, possibly merged with targets
whose visible regions touch, possibly split into fragments (always where an occluder cuts it
apart); Poisson clutter is added; confidences are Beta-distributed, higher for true detections and
rising with visibility. ``foreground`` runs background subtraction, morphology and connected
components on the rendered frame, so fragments and merges come from the image itself.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from .scenario import Scenario, SensorConfig
from .truth import Truth, clip_boxes, overlapping_pairs

CLUTTER = -1   # source of a false detection
UNKNOWN = 0    # source of a foreground blob (the image does not say which target made it)


@dataclass(frozen=True)
class Detections:
    """One frame's detections: rows x, y, w, h, confidence, and the target id behind each (for tests and overlays)."""

    rows: np.ndarray     # (n, 5) float32
    sources: np.ndarray  # (n,) int64: target id, CLUTTER or UNKNOWN


def detection_probability(visibility: np.ndarray, cfg: SensorConfig) -> np.ndarray:
    """pd ** (1 / ramp), ramp = (visibility - min_visibility) / (1 - min_visibility) in (0, 1]; 0 where ramp <= 0.

    pd at full view, rising with visibility, none at or below min_visibility, and every visible target when pd = 1.
    """
    ramp = np.clip((visibility - cfg.min_visibility) / max(1e-9, 1 - cfg.min_visibility), 0, 1)
    return np.where(ramp > 0, cfg.pd ** (1 / np.maximum(ramp, 1e-9)), 0.0)


def _union(boxes: np.ndarray, groups: np.ndarray, n_groups: int) -> np.ndarray:
    """Union box of the boxes in each group."""
    lo = np.full((n_groups, 2), np.inf)
    hi = np.full((n_groups, 2), -np.inf)
    np.minimum.at(lo, groups, boxes[:, :2])
    np.maximum.at(hi, groups, boxes[:, :2] + boxes[:, 2:])
    return np.concatenate([lo, hi - lo], axis=1)


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
    out[:, 2 + axis] = np.diff(edges) - gap / 2 * ((np.arange(k) > 0) + (np.arange(k) < k - 1))
    return out


class Sensor:
    """What both detector models share: box noise, confidences, clutter and the observation limits."""

    def __init__(self, sc: Scenario, rng: np.random.Generator):
        self.cfg, self.rng = sc.sensor, rng
        self.size = (sc.render.width, sc.render.height)
        self.nominal = np.array([g.size for g in sc.groups], float)

    def _confidence(self, mean: np.ndarray) -> np.ndarray:
        k = self.cfg.conf_spread
        mean = np.clip(mean, 1e-3, 1 - 1e-3)
        return self.rng.beta(mean * k, (1 - mean) * k)

    def _jitter(self, boxes: np.ndarray) -> np.ndarray:
        """Centre noise and size noise proportional to the box size, and the systematic scale."""
        noise = self.rng.normal(0, self.cfg.box_noise, (len(boxes), 4))
        c = boxes[:, :2] + boxes[:, 2:] / 2 + noise[:, :2] * boxes[:, 2:]
        wh = boxes[:, 2:] * self.cfg.box_scale * np.exp(noise[:, 2:])
        return np.concatenate([c - wh / 2, wh], axis=1)

    def _clutter(self, truth: Truth) -> np.ndarray:
        """Poisson false boxes, uniformly placed, sized like the current targets."""
        n = self.rng.poisson(self.cfg.clutter_rate)
        if not n:
            return np.zeros((0, 4))
        pool = truth.boxes[:, 2:] if len(truth) else self.nominal
        wh = pool[self.rng.integers(len(pool), size=n)] * np.exp(self.rng.normal(0, 0.3, (n, 2)))
        wh = np.minimum(wh, np.array(self.size) * 0.5)
        xy = self.rng.uniform(0, 1, (n, 2)) * (np.array(self.size) - wh)
        return np.concatenate([xy, wh], axis=1)

    def _finish(self, boxes: np.ndarray, mean_conf: np.ndarray, sources: np.ndarray, truth: Truth) -> Detections:
        """Add clutter, draw confidences, clip to the image, drop degenerate boxes, shuffle, keep max_detections."""
        cb = self._clutter(truth)
        if len(cb):
            boxes = np.concatenate([boxes, cb])
            mean_conf = np.concatenate([mean_conf, np.full(len(cb), self.cfg.conf_false)])
            sources = np.concatenate([sources, np.full(len(cb), CLUTTER)])
        conf = self._confidence(mean_conf)
        boxes = clip_boxes(boxes, *self.size)
        order = self.rng.permutation(np.flatnonzero((boxes[:, 2] >= 1) & (boxes[:, 3] >= 1)))
        if len(order) > self.cfg.max_detections:  # keep the most confident, in their shuffled order
            order = order[np.sort(np.argsort(-conf[order], kind="stable")[: self.cfg.max_detections])]
        rows = np.empty((len(order), 5), np.float32)
        rows[:, :4], rows[:, 4] = boxes[order], conf[order]
        return Detections(rows, sources[order].astype(np.int64))


class SyntheticSensor(Sensor):
    """Detections made from the label map and the truth (no image processing)."""

    def detect(self, truth: Truth, labels: np.ndarray, frame: np.ndarray | None = None) -> Detections:
        cfg, rng = self.cfg, self.rng
        pd = detection_probability(truth.visibility, cfg)
        cand = np.flatnonzero(pd > 0)
        obj = self._merge_groups(truth, labels, cand)
        n_obj = int(obj.max()) + 1 if len(obj) else 0
        if n_obj == len(cand):  # nothing merged: one object per candidate target
            box, p, vis, lead = truth.visible_boxes[cand], pd[cand], truth.visibility[cand], cand
        else:
            box = _union(truth.visible_boxes[cand], obj, n_obj)
            p, vis = np.zeros(n_obj), np.zeros(n_obj)
            np.maximum.at(p, obj, pd[cand])
            np.maximum.at(vis, obj, truth.visibility[cand])
            area = np.prod(truth.visible_boxes[cand, 2:], axis=1)
            order = np.lexsort((area, obj))  # the member with the largest visible area names the object
            lead = cand[order[np.r_[np.flatnonzero(np.diff(obj[order])), len(order) - 1]]]
        single = np.bincount(obj, minlength=n_obj) == 1
        hit = rng.random(n_obj) < p
        mean = cfg.conf_true * (0.5 + 0.5 * vis)
        owners = truth.pieces[:, 0].astype(int)
        cut = hit & single & np.isin(lead, owners) if len(owners) else np.zeros(n_obj, bool)  # cut apart: report pieces
        split = hit & single & ~cut & (rng.random(n_obj) < cfg.fragment_prob)
        whole = hit & ~cut & ~split
        mean_of = np.zeros(len(truth))
        mean_of[lead] = mean
        piece = np.isin(owners, lead[cut]) if len(owners) else np.zeros(0, bool)
        boxes = [box[whole], truth.pieces[piece, 1:]]
        means = [mean[whole], 0.8 * mean_of[owners[piece]]]
        sources = [truth.ids[lead[whole]], truth.ids[owners[piece]]]
        for o in np.flatnonzero(split):
            parts = _split(box[o], int(rng.integers(2, 4)), rng)
            boxes.append(parts)
            means.append(np.full(len(parts), 0.8 * mean[o]))
            sources.append(np.full(len(parts), truth.ids[lead[o]]))
        b = np.concatenate(boxes)
        if cfg.box_noise or cfg.box_scale != 1:
            b = self._jitter(b)
        return self._finish(b, np.concatenate(means), np.concatenate(sources), truth)

    def _merge_groups(self, truth: Truth, labels: np.ndarray, cand: np.ndarray) -> np.ndarray:
        """Object index of each candidate: targets whose visible regions touch are linked with merge_prob."""
        n = len(cand)
        if n < 2 or self.cfg.merge_prob <= 0:
            return np.arange(n)
        vb = truth.visible_boxes[cand]
        i, j = overlapping_pairs(vb, margin=1.0)
        linked = self.rng.random(len(i)) < self.cfg.merge_prob
        i, j = i[linked], j[linked]
        if not len(i):
            return np.arange(n)
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

    def __init__(self, sc: Scenario, rng: np.random.Generator, background: np.ndarray):
        super().__init__(sc, rng)
        self.model = cv2.cvtColor(background, cv2.COLOR_RGB2GRAY).astype(np.float32)
        self.open = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (3, 3))
        self.close = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5))

    def detect(self, truth: Truth, labels: np.ndarray, frame: np.ndarray | None = None) -> Detections:
        if frame is None:
            raise ValueError("the foreground sensor needs the rendered frame")
        cfg = self.cfg
        gray = cv2.cvtColor(frame, cv2.COLOR_RGB2GRAY)
        diff = cv2.absdiff(gray, cv2.convertScaleAbs(self.model))
        mask = (diff > cfg.threshold).astype(np.uint8)
        mask = cv2.morphologyEx(cv2.morphologyEx(mask, cv2.MORPH_OPEN, self.open), cv2.MORPH_CLOSE, self.close)
        count, comp, stats, _ = cv2.connectedComponentsWithStatsWithAlgorithm(mask, 8, cv2.CV_32S, cv2.CCL_GRANA)
        cv2.accumulateWeighted(gray, self.model, cfg.learning_rate, mask=1 - mask)
        area = stats[1:, cv2.CC_STAT_AREA].astype(float)
        keep = np.flatnonzero(area >= max(cfg.min_area, 1))
        contrast = np.bincount(comp.ravel(), weights=diff.ravel(), minlength=count)[1:][keep] / area[keep]
        # confidence: strong contrast and a target-sized area make a blob believable
        mean = np.clip(contrast / (4 * cfg.threshold), 0, 1) * (1 - np.exp(-area[keep] / (5 * max(cfg.min_area, 1))))
        boxes = stats[1:][keep, :4].astype(float)
        return self._finish(boxes, mean, np.full(len(keep), UNKNOWN), truth)


def make_sensor(sc: Scenario, rng: np.random.Generator, background: np.ndarray) -> Sensor:
    """The scenario's detector; `background` (an empty frame) seeds the foreground model."""
    if sc.sensor.model == "foreground":
        return ForegroundSensor(sc, rng, background)
    return SyntheticSensor(sc, rng)
