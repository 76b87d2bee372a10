"""Liu et al. (2011): the interactive particle filter, tracking several targets through full occlusion."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .base import Param, Tracker, Tracks, frame_of
from .parts.appearance import bhattacharyya, histograms, hs_bins
from .parts.near_pairs import near_in_x_and_y
from .parts.particles import crop_around, image_size, initial_targets, systematic_resample


def conflict_set(centres: np.ndarray, sizes: np.ndarray, ratio: float) -> np.ndarray:
    """Eq. 2: which particles (targets, N) overlap a particle of another target by more than `ratio` of the smaller
    region. Regions are each target's box size centred on its particles. Only particle pairs near enough to pass
    are compared (a sweep along x, then y), so a crowd costs its near pairs rather than (KN)^2 overlaps."""
    k, n, _ = centres.shape
    owner = np.repeat(np.arange(k), n)
    xy, half = centres.reshape(-1, 2), np.repeat(sizes / 2.0, n, axis=0)
    a, b = near_in_x_and_y(xy, _reach(sizes, ratio)[owner], xy)
    other = owner[a] != owner[b]
    a, b = a[other], b[other]
    overlap = np.clip(np.minimum(xy[a] + half[a], xy[b] + half[b]) - np.maximum(xy[a] - half[a], xy[b] - half[b]), 0, None)
    area = np.prod(sizes, axis=1)
    hit = overlap[:, 0] * overlap[:, 1] > ratio * np.minimum(area[owner[a]], area[owner[b]])
    conflict = np.zeros(k * n, bool)
    conflict[a[hit]] = True
    return conflict.reshape(k, n)


def _reach(sizes: np.ndarray, ratio: float) -> np.ndarray:
    """(targets, 2): the largest |dx|, |dy| at which a particle of a target can overlap one of another by more than
    `ratio` of the smaller region. Overlap in x is at most (w_a + w_b) / 2 - |dx| and in y at most min(h_a, h_b),
    so the product exceeds ratio min(area) only if |dx| < (w_a + w_b) / 2 - ratio min(area) / min(h_a, h_b)."""
    w, h = sizes[:, 0], sizes[:, 1]
    need = ratio * np.minimum.outer(w * h, w * h)
    reach = np.stack([np.add.outer(w, w) / 2 - need / np.minimum.outer(h, h),
                      np.add.outer(h, h) / 2 - need / np.minimum.outer(w, w)], axis=-1)  # (K, K, 2)
    reach[np.arange(len(w)), np.arange(len(w))] = 0.0  # a target's own particles do not conflict
    return np.maximum(reach.max(axis=1, initial=0.0), 0.0) * (1 + 1e-9) + 1e-9  # rounding: keep every candidate


class InteractiveParticleFilter(Tracker):
    """One particle set of N particles per initial target (boxes from env.reset's info["init_boxes"], as the paper
    initialises by hand). Particles are drawn around the target's previous estimate with a Brownian step of
    sigma = sqrt(area(R_k)) / 2 (eq. 3). Each particle's region (the target's box size) gets a hue-saturation
    histogram; the likelihood against a template is a Gaussian in the Bhattacharyya distance with sigma^2 = 0.045
    (eq. 6-7); templates are fixed at the first frame, as in the paper. Particles whose regions overlap a particle of
    another target by more than lambda = 0.75 of the smaller region form the conflict set (eq. 2); such a particle
    is visible if its own template scores best among all targets' templates, and otherwise is weighted with the
    best template's likelihood divided by its distance to the target's previous estimate (eq. 4). The state is the
    weighted mean (eq. 5), kept inside the image (the paper does not say; a target that leaves the view, or a
    coasting estimate, would otherwise drift off without bound). interactive=false weighs every particle with its own
    template (independent filters).
    Histograms use a regular sample of about `samples` pixels of each region (every pixel with samples=0, as in
    the paper): the four books of `books` x 100 particles would otherwise be 4.3 million pixels a frame."""

    name = "ipf"
    description = "Interactive particle filter through full occlusion (Liu et al. 2011; hand-initialised)"
    parameters = {
        "particles": Param(100, "[1, 100000]", "particles per target"),
        "conflict_ratio": Param(0.75, "(0, 1]", "overlap (of the smaller box) that puts two targets' particles in "
                                                "conflict", (0.3, 0.95)),
        "sigma2": Param(0.045, "(0, inf)", "variance of the colour likelihood (eq. 6)", (0.005, 0.5, "log")),
        "h_levels": Param(16, "[2, 180]", "hue histogram levels", (4, 64, "log")),
        "s_levels": Param(16, "[2, 256]", "saturation histogram levels", (4, 64, "log")),
        "interactive": Param(True, None, "reweight conflicting particles (false: independent filters)"),
        "samples": Param(256, "[0, inf)", "pixels sampled per region for its histogram (0: all)"),
        "propagate": Param("estimate", ("estimate", "resample"),
                           "estimate: every particle drawn around the previous estimate (sec. 3.2: the particles "
                           "follow a Gaussian whose mean is the target's position at t-1); resample: the previous "
                           "particles resampled by weight, then each moved by the Brownian step (eq. 3 after sec. "
                           "2's selection step)"),
        "spread": Param("std", ("std", "variance"),
                        "how to read delta = sqrt(area(R_k)) / 2 of eq. 3: as the step's standard deviation (the "
                        "paper names eq. 6's sigma its 'variance' while writing sigma^2 = 0.045), or literally as "
                        "its variance"),
        "seed": Param(0, "[0, inf)", "the particles' random seed")}
    needs_frame = True

    def reset(self, info=None):
        self.ids, self.estimates, self.sizes = initial_targets(info)
        self.image_size = image_size(info)
        delta = np.sqrt(np.prod(self.sizes, axis=1)) / 2
        self.sigma = delta if self.params["spread"] == "std" else np.sqrt(delta)
        self.rng = np.random.default_rng(self.params["seed"])
        self.templates = None
        self._cloud = (np.zeros((0, 0, 2)), np.zeros((0, 0)), np.zeros((0, 0), bool))

    def _histograms(self, frame: np.ndarray, centres: np.ndarray, size) -> np.ndarray:
        p = self.params
        origin, crop = crop_around(frame, centres, size)
        bins = hs_bins(crop, p["h_levels"], p["s_levels"])
        stride = max(1, int(np.sqrt(np.prod(size) / p["samples"]))) if p["samples"] else 1
        return histograms(bins, p["h_levels"] * p["s_levels"], centres - origin, tuple(size), stride=stride)

    def _centres(self) -> np.ndarray:
        """(targets, N or 1, 2): what each particle's Brownian step starts from: the prediction, or (propagate=resample,
        after the first frame) the previous particles drawn by weight and moved as the prediction moved."""
        prediction = self._predict()
        previous, weights, _ = self._cloud
        if self.params["propagate"] == "estimate" or not previous.size:
            return prediction[:, None]
        drawn = np.take_along_axis(previous, systematic_resample(weights, self.rng)[:, :, None], axis=1)
        return drawn + (prediction - self.estimates)[:, None]

    def _predict(self) -> np.ndarray:
        """Where each target's particles are centred (eq. 3: a Brownian step from the previous estimate)."""
        return self.estimates

    def _settle(self, estimates: np.ndarray, best_distance2: np.ndarray) -> np.ndarray:
        """The new estimates, given each target's weighted mean and its best particle's distance to its template."""
        return estimates

    def update(self, obs) -> Tracks:
        p = self.params
        frame = frame_of(obs)
        k, n = len(self.ids), p["particles"]
        if self.templates is None:
            self.templates = np.array([self._histograms(frame, c[None], s)[0] for c, s in zip(self.estimates, self.sizes)])
        particles = self._centres() + self.rng.normal(0, 1, (k, n, 2)) * self.sigma[:, None, None]
        hists = [self._histograms(frame, particles[t], self.sizes[t]) for t in range(k)]
        # eq. 7's squared Bhattacharyya distance of every particle to every template, (targets, N, templates),
        # and eq. 6's Gaussian likelihood
        d2 = np.clip(1.0 - np.stack([bhattacharyya(h, self.templates) for h in hists]), 0.0, None) \
            if k else np.zeros((0, n, 0))
        s2 = p["sigma2"]
        like = np.exp(-d2 / (2 * s2)) / np.sqrt(2 * np.pi * s2)
        own = like[np.arange(k), :, np.arange(k)] if k else np.zeros((0, n))
        weights = own.copy()
        if p["interactive"] and k > 1:
            conflict = conflict_set(particles, self.sizes.astype(float), p["conflict_ratio"])
            best = like.max(axis=2)
            hidden = conflict & (own < best)
            distance = np.maximum(np.linalg.norm(particles - self.estimates[:, None], axis=2), 1.0)
            weights = np.where(hidden, best / distance, own)
        total = weights.sum(axis=1, keepdims=True)
        weights = np.where(total > 0, weights / np.where(total > 0, total, 1.0), 1.0 / n)
        own_d2 = d2[np.arange(k), :, np.arange(k)] if k else np.zeros((0, n))
        estimates = self._settle(np.einsum("kn,knd->kd", weights, particles), own_d2.min(axis=1, initial=1.0))
        self.estimates = np.clip(estimates, 0, self.image_size)  # the state is a position in the image (deviation)
        self._cloud = (particles, weights, hidden if p["interactive"] and k > 1 else np.zeros((k, n), bool))
        boxes = np.c_[self.estimates - self.sizes / 2, self.sizes]
        return Tracks.of(self.ids, boxes, weights.max(axis=1) if k else np.zeros(0))

    def debug(self) -> list[dict]:
        """Each target's particles, their weights and which of them the interaction reweighted (hidden: inside
        another target's conflict set, where that target explains the image better)."""
        xy, w, hidden = self._cloud
        return [{"kind": "points", "xy": xy[t], "weights": w[t], "hidden": hidden[t], "id": int(self.ids[t])}
                for t in range(len(xy))]


class PathConsistencyParticleFilter(InteractiveParticleFilter):
    """The baseline the interactive filter's paper compares against: independent particle filters (200 particles
    each, the paper's count for it) that assume a consistent path. Particles are drawn around the constant-velocity prediction, and while a
    target's best particle is farther than `occluded_distance` (squared Bhattacharyya distance) from its template
    the target is taken as occluded and coasts on its velocity instead of following its weights."""

    name = "pcpf"
    description = "The interactive filter's baseline: path-consistency (constant-velocity) particle filters " \
                  "(hand-initialised)"
    parameters = {
        **InteractiveParticleFilter.parameters,
        "particles": Param(200, "[1, 100000]", "particles per target (the paper's count for this baseline)"),
        "interactive": Param(False, None, "off: independent filters, the baseline"),
        # read only when interactive: not tuned here
        "conflict_ratio": replace(InteractiveParticleFilter.parameters["conflict_ratio"], search=()),
        "occluded_distance": Param(0.3, "[0, 1]", "a target whose best particle is farther than this is occluded and "
                                                  "coasts", (0.05, 0.8)),
        "velocity_gain": Param(0.3, "[0, 1]", "how fast the velocity follows the estimates", (0.05, 0.9))}

    def reset(self, info=None):
        super().reset(info)
        self.velocity = np.zeros_like(self.estimates)
        self.occluded = np.zeros(len(self.ids), bool)

    def _predict(self) -> np.ndarray:
        return self.estimates + self.velocity

    def _settle(self, estimates: np.ndarray, best_distance2: np.ndarray) -> np.ndarray:
        self.occluded = best_distance2 > self.params["occluded_distance"]
        g = self.params["velocity_gain"]
        velocity = (1 - g) * self.velocity + g * (estimates - self.estimates)
        self.velocity = np.where(self.occluded[:, None], self.velocity, velocity)
        return np.where(self.occluded[:, None], self.estimates + self.velocity, estimates)
