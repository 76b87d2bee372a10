"""The Gaussian-mixture PHD filter (Vo and Ma 2006) with measurement-driven birth and labelled components: the
"GMPHD" comparator of the LMB paper."""

from __future__ import annotations


import numpy as np

from .base import Param, Tracker, Tracks, detections
from .parts import gaussian_mixture as gm
from .parts.assignment import chi2_gate


class GaussianMixturePhd(Tracker):
    """The PHD (first moment of the multi-target density) as a Gaussian mixture over (x, y, w, h, vx, vy, vw, vh).
    Predict: weights times the survival probability. Update (Vo and Ma 2006, Table I): missed components with
    weight (1 - P_D) w, and for each detection z the components P_D w N(z) / (clutter density + sum of
    P_D w N(z)), inside a chi-square gate. Birth is measurement-driven: each detection the mixture explains by
    less than one target gives a newborn component at the next frame with weight `birth_weight` x confidence x
    (1 - how much it is explained). Components under `prune` are dropped, those within Mahalanobis distance
    `merge` of the heaviest are merged into it, at most `max_components` are kept. States with weight > 0.5 are
    reported.
    Labels (the filter has none of its own): a component carries the label of the component it was corrected
    from, a newborn one a fresh label, a merged one the label of the heaviest; when two reported states share a
    label, the heavier keeps it and the other takes a fresh one (Panta, Clark and Vo 2009, "tagging")."""

    name = "gmphd"
    description = "GM-PHD filter (Vo and Ma 2006), measurement-driven birth, labels tagged through updates"
    parameters = {
        **gm.MODEL_PARAMETERS,  # the model lmb shares, with where a tuner looks
        "birth_weight": Param(0.3, "(0, inf)", "newborn weight per unexplained detection (times its confidence)",
                              (0.03, 1.0, "log")),
        "prune": Param(1e-4, "[0, 1)", "components lighter than this are dropped"),
        "merge": Param(4.0, "[0, inf)", "Mahalanobis distance within which components merge", (1.0, 16.0, "log")),
        "max_components": Param(200, "[1, inf)", "most components kept"),
        "extract": Param(0.5, "(0, inf)", "least weight of a reported state", (0.2, 0.9))}

    def reset(self, info=None):
        size = (info or {}).get("image_size")
        if size is None or min(size) <= 0:
            raise ValueError("gmphd needs the image size (clutter density): pass env.reset's info")
        w, h = (float(v) for v in size)
        self.clutter_density = self.params["clutter_rate"] / (w * h * (w / 4) * (h / 2))
        self.noise = gm.BoxNoise(self.params["measurement_noise"], self.params["process_noise"])
        self.w, self.label = np.zeros(0), np.zeros(0, np.int64)
        self.m, self.P = np.zeros((0, gm.DIM)), np.zeros((0, gm.DIM, gm.DIM))
        self.pending = (np.zeros((0, 4)), np.zeros(0))
        self.next_label = 1

    def _fresh(self, n: int) -> np.ndarray:
        out = np.arange(self.next_label, self.next_label + n)
        self.next_label += n
        return out

    def update(self, obs) -> Tracks:
        p = self.params
        dets = detections(obs)
        z, conf = dets[:, :4], dets[:, 4]
        pd = p["detection"]
        m, P = gm.predict(self.m, self.P, self.noise)
        bm, bP = self.noise.birth(self.pending[0])
        w = np.r_[self.w * p["survival"], self.pending[1]]
        label = np.r_[self.label, self._fresh(len(bm))]
        m, P = np.r_[m, bm], np.concatenate([P, bP])

        inn = gm.Innovation.of(m, P, self.noise)
        d2 = inn.distance2(z, chi2_gate(gm.MEAS, p["gate"]))
        gated = np.isfinite(d2)
        like = np.where(gated, pd * w[:, None] * np.exp(inn.log_likelihood(d2)), 0.0)  # (C, M)
        share = like / (self.clutter_density + like.sum(axis=0))
        c, j = np.nonzero(share > p["prune"])
        explained = share.sum(axis=0)
        self.pending = (z, p["birth_weight"] * conf * np.clip(1 - explained, 0, 1))

        w = np.r_[(1 - pd) * w, share[c, j]]
        m = np.r_[m, inn.corrected_means(m, z, c, j)]
        P = np.concatenate([P, inn.P[c]])
        label = np.r_[label, label[c]]
        self._prune_and_merge(w, m, P, label)

        report = np.flatnonzero(self.w > p["extract"])
        labels = self.label[report]
        _, first = np.unique(labels, return_index=True)   # components are sorted heaviest first
        dup = np.setdiff1d(np.arange(len(report)), first)
        self.label[report[dup]] = labels[dup] = self._fresh(len(dup))
        return Tracks.of(labels, self.m[report, :4], np.minimum(self.w[report], 1.0))

    def _prune_and_merge(self, w, m, P, label) -> None:
        """Vo and Ma's Table II: drop light components, merge each heaviest one with its neighbours, keep the
        heaviest `max_components`; the result is sorted heaviest first."""
        p = self.params
        keep = w > p["prune"]
        w, m, P, label = w[keep], m[keep], P[keep], label[keep]
        order = np.argsort(-w, kind="stable")
        w, m, P, label = w[order], m[order], P[order], label[order]
        near = gm.within_distance(m, P, p["merge"])
        head_of = np.full(len(w), -1)
        heads = []
        for k in range(len(w)):  # the heaviest open component takes its open neighbours (itself among them)
            if head_of[k] >= 0:
                continue
            if len(heads) == p["max_components"]:
                break
            members = near[k][head_of[near[k]] < 0]
            head_of[members] = len(heads)
            heads.append(k)
        heads = np.array(heads, np.int64)
        total, mean, cov = merge_clusters(w, m, P, head_of, len(heads))
        order = np.argsort(-total, kind="stable")
        self.w, self.label = total[order], label[heads][order]
        self.m = mean.reshape(-1, gm.DIM)[order]
        self.P = cov.reshape(-1, gm.DIM, gm.DIM)[order]


def merge_clusters(w, m, P, cluster, count):
    """Weight, mean and covariance of each of `count` clusters of weighted Gaussians (cluster index -1: dropped).
    Clusters of one are copied through the same arithmetic at once; larger ones are summed one by one in the
    order the filter always used, so results stay identical to the bit."""
    total, mean, cov = np.zeros(count), np.zeros((count, gm.DIM)), np.zeros((count, gm.DIM, gm.DIM))
    size = np.bincount(cluster[cluster >= 0], minlength=count)
    alone = np.flatnonzero((cluster >= 0) & (size[np.maximum(cluster, 0)] == 1))
    c, wa = cluster[alone], w[alone]
    total[c] = wa
    mean[c] = wa[:, None] * m[alone] / wa[:, None]
    spread = m[alone] - mean[c]
    cov[c] = (wa[:, None, None] * P[alone] + wa[:, None, None] * spread[:, :, None] * spread[:, None, :]) / wa[:, None, None]
    for c in np.flatnonzero(size > 1).tolist():
        near = np.flatnonzero(cluster == c)
        wn = w[near]
        total[c] = wn.sum()
        mean[c] = wn @ m[near] / total[c]
        spread = m[near] - mean[c]
        cov[c] = (np.einsum("n,nij->ij", wn, P[near]) + np.einsum("n,ni,nj->ij", wn, spread, spread)) / total[c]
    return total, mean, cov
