"""Li, Zhang and Li (2007): a particle filter fusing a colour histogram with a gradient-orientation texture
descriptor, with a template update guarded against occlusion."""

from __future__ import annotations

import numpy as np

from .base import Param, Tracker, Tracks, frame_of
from .parts.appearance import bhattacharyya, gradient_descriptors, histograms, orientation_maps, rgb_bins
from .parts.particles import crop_around, image_size, initial_targets, systematic_resample


class ColourTextureParticleFilter(Tracker):
    """One particle filter per initial target (boxes from env.reset's info["init_boxes"], as the paper initialises
    by hand). State (x, y, vx, vy) with the constant-velocity model of eq. 3 and Gaussian noise. Each particle's
    region (the initial box size) gets an RGB histogram of levels^3 bins (16 levels: 4096 bins) and a 4 x 4 x 8
    gradient-orientation vector; likelihoods exp(-lam d^2), d^2 = 1 - Bhattacharyya coefficient (eq. 4-6), and
    exp(-mu e^2), e the Euclidean distance of the descriptors (eq. 7), fused as p_color^alpha p_texture^(1-alpha)
    (eq. 8; alpha = 1 is colour only). The estimate is the weighted mean; the templates are updated with beta
    (eq. 9-10) only when the estimate's likelihood exceeds update_threshold, so occluders do not enter them.
    Particles' positions are kept inside the image (a deviation: the paper does not say, and a drifting velocity
    would otherwise carry a lost target's particles off without bound).
    The paper's lam = 0.02 and mu = 0.01 make both likelihoods nearly flat at our scales (d^2 lies in [0, 1], e^2
    in [0, 4]), so the defaults are 20 and 10; pass lam=0.02,mu=0.01 for the paper's values."""

    name = "pf"
    description = "Colour + gradient-orientation particle filter with template update (Li, Zhang and Li 2007; " \
                  "hand-initialised)"
    parameters = {
        "particles": Param(60, "[1, 100000]", "particles per target"),
        "alpha": Param(0.6, "[0, 1]", "weight of colour against texture in the fused likelihood", (0.0, 1.0)),
        "lam": Param(20.0, "(0, inf)", "colour likelihood exp(-lam d^2) (the paper: 0.02)", (4.0, 200.0, "log")),
        "mu": Param(10.0, "(0, inf)", "texture likelihood exp(-mu e^2) (the paper: 0.01)", (2.0, 50.0, "log")),
        "beta": Param(0.9, "[0, 1]", "template memory in the update (eq. 9-10)", (0.5, 1.0)),
        "update_threshold": Param(0.3, "[0, 1]", "least likelihood of the estimate for a template update",
                                  (0.05, 0.9)),
        "pos_sigma": Param(3.0, "[0, inf)", "position noise per frame, px", (1.0, 30.0, "log")),
        "vel_sigma": Param(1.0, "[0, inf)", "velocity noise per frame, px/frame", (0.2, 10.0, "log")),
        "levels": Param(16, "[2, 64]", "histogram levels per colour channel", (4, 32, "log")),
        "seed": Param(0, "[0, inf)", "the particles' random seed")}
    needs_frame = True

    def reset(self, info=None):
        self.ids, self.start, self.sizes = initial_targets(info)
        self.image_size = image_size(info)
        self.rng = np.random.default_rng(self.params["seed"])
        self.particles = None  # (targets, N, 4), made at the first frame
        self.templates: list[tuple[np.ndarray, np.ndarray]] = []

    def _maps(self, frame: np.ndarray, centres: np.ndarray, size: np.ndarray):
        """Bin and gradient maps of the crop that holds every region of one target: (origin, maps)."""
        origin, crop = crop_around(frame, centres, size)
        return origin, (rgb_bins(crop, self.params["levels"]), *orientation_maps(crop))

    def _features(self, maps, centres: np.ndarray, size) -> tuple[np.ndarray, np.ndarray]:
        bins, orient, magnitude = maps
        return (histograms(bins, self.params["levels"] ** 3, centres, tuple(size)),
                gradient_descriptors(orient, magnitude, centres, tuple(size)))

    def _particle_likelihoods(self, maps, centres: np.ndarray, size, template) -> np.ndarray:
        """Eq. 8 for every region: colour histograms are counted over the template's nonzero bins alone, the only
        ones its Bhattacharyya coefficient reads (a few hundred of 4096), so the same coefficients cost far less."""
        bins, orient, magnitude = maps
        support = np.flatnonzero(template[0])
        compact = np.full(self.params["levels"] ** 3, len(support))
        compact[support] = np.arange(len(support))
        hist = histograms(compact[bins], len(support) + 1, centres, tuple(size))[:, :-1]
        return self._likelihood(bhattacharyya(hist, template[0][support]),
                                gradient_descriptors(orient, magnitude, centres, tuple(size)), template)

    def _likelihood(self, rho: np.ndarray, descriptors: np.ndarray, template) -> np.ndarray:
        """Eq. 4-8 from the Bhattacharyya coefficients and the texture descriptors of the regions."""
        p = self.params
        colour = np.exp(-p["lam"] * (1 - rho))
        texture = np.exp(-p["mu"] * ((descriptors - template[1][None]) ** 2).sum(axis=1))
        return colour ** p["alpha"] * texture ** (1 - p["alpha"])

    def update(self, obs) -> Tracks:
        p = self.params
        frame = frame_of(obs)
        n, k = p["particles"], len(self.ids)
        if self.particles is None:
            self.templates = []
            for c, size in zip(self.start, self.sizes):
                origin, maps = self._maps(frame, c[None], size)
                hist, desc = self._features(maps, c[None] - origin, size)
                self.templates.append((hist[0], desc[0]))
            self.particles = np.zeros((k, n, 4))
            self.particles[:, :, :2] = self.start[:, None] + self.rng.normal(0, p["pos_sigma"], (k, n, 2))
        else:  # eq. 3: X_t = Phi X_{t-1} + W
            self.particles[:, :, :2] += self.particles[:, :, 2:]
            self.particles += self.rng.normal(0, 1, (k, n, 4)) * [p["pos_sigma"], p["pos_sigma"], p["vel_sigma"],
                                                                  p["vel_sigma"]]
        self.particles[:, :, :2] = np.clip(self.particles[:, :, :2], 0, self.image_size)  # positions in the image
        weights = np.ones((k, n)) / n
        estimates, scores = np.zeros((k, 4)), np.zeros(k)
        for t in range(k):  # targets differ in region size; every particle of a target is one batched call
            origin, maps = self._maps(frame, self.particles[t, :, :2], self.sizes[t])
            like = self._particle_likelihoods(maps, self.particles[t, :, :2] - origin, self.sizes[t], self.templates[t])
            if like.sum() > 0:
                weights[t] = like / like.sum()
            estimates[t] = weights[t] @ self.particles[t]
            feats = self._features(maps, estimates[t, None, :2] - origin, self.sizes[t])
            scores[t] = self._likelihood(bhattacharyya(feats[0], self.templates[t][0]), feats[1], self.templates[t])[0]
            if scores[t] > p["update_threshold"]:  # eq. 9-10, only on a confident estimate
                q, r = self.templates[t]
                self.templates[t] = (p["beta"] * q + (1 - p["beta"]) * feats[0][0],
                                     p["beta"] * r + (1 - p["beta"]) * feats[1][0])
        self._cloud = (self.particles[:, :, :2].copy(), weights.copy())
        picks = systematic_resample(weights, self.rng)
        self.particles = np.take_along_axis(self.particles, picks[:, :, None], axis=1)
        boxes = np.c_[estimates[:, :2] - self.sizes / 2, self.sizes]
        return Tracks.of(self.ids, boxes, scores)

    def debug(self) -> list[dict]:
        """Each target's particle cloud (positions and weights) before resampling."""
        if self.particles is None:
            return []
        xy, w = self._cloud
        return [{"kind": "points", "xy": xy[t], "weights": w[t], "id": int(self.ids[t])} for t in range(len(xy))]
