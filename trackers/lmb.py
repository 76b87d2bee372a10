"""Jiang and Yang: a labelled multi-Bernoulli filter with Gaussian-mixture densities, gating and grouping,
Murty-ranked association hypotheses, and a birth model driven by the detections and their confidences."""

from __future__ import annotations

import math

import numpy as np

from .base import Param, Tracker, Tracks, covariance_ellipse, detections, frame_of
from .parts import gaussian_mixture as gm
from .parts import reid
from .parts.assignment import chi2_gate, clusters, murty
from .parts.camera_motion import METHODS, CameraMotion, warp_boxes, warp_centres

EPS = 1e-12
ENUMERATE_UP_TO = 4096  # groups with at most this many candidate hypotheses (an upper bound) are enumerated


def factor_table(log_r: np.ndarray, log_q: np.ndarray, pd: float) -> np.ndarray:
    """(n, m + 2) log factors of each track's choices: measurement j (r pD q_j / kappa), missed (r (1 - pD)),
    dead (1 - r)."""
    log_1mr = np.log1p(-np.minimum(np.exp(log_r), 1 - EPS))
    log_miss = np.log1p(-pd) if pd < 1 else -np.inf
    return np.column_stack([log_r[:, None] + np.log(pd) + log_q, log_r + log_miss, log_1mr])


def group_update(log_r: np.ndarray, log_q: np.ndarray, pd: float, hypotheses: int) -> np.ndarray:
    """The LMB update of one group (Reuter et al. 2014, sec. III): the predicted LMB is a delta-GLMB whose
    `hypotheses` best association hypotheses are kept, then turned back into an LMB. A hypothesis gives each track
    a measurement (none twice), "missed" or "dead", with weight prod r pD q / kappa, r (1 - pD) or 1 - r.
    `log_r` (n,) log existence, `log_q` (n, m) log(q(z) / clutter density), -inf outside the gate.
    Murty's algorithm ranks them on the cost matrix [detections | missed | dead]; a group with at most
    ENUMERATE_UP_TO candidate hypotheses lists them all and keeps the same best ones without it.
    Returns beta (n, m + 1): the probability that track i exists and took measurement j, or (last column) exists
    and was missed; row sums are the posterior existence probabilities."""
    n, m = log_q.shape
    table = factor_table(log_r, log_q, pd)
    options = [np.flatnonzero(row) for row in np.isfinite(table)]
    if math.prod(len(o) for o in options) <= ENUMERATE_UP_TO:
        choice = cartesian_product(options)
        distinct = np.sort(np.where(choice < m, choice, m + 2 + np.arange(n)), axis=1)
        choice = choice[(np.diff(distinct, axis=1) != 0).all(axis=1)]
        log_w = table[np.arange(n), choice].sum(axis=1)
        if len(log_w) > hypotheses:
            top = np.argpartition(-log_w, hypotheses - 1)[:hypotheses]
            choice, log_w = choice[top], log_w[top]
    else:
        cost = np.full((n, m + 2 * n), np.inf)
        rows = np.arange(n)
        cost[:, :m], cost[rows, m + rows], cost[rows, m + n + rows] = -table[:, :m], -table[:, m], -table[:, m + 1]
        ranked = murty(cost, hypotheses)
        cols = np.stack([c for c, _ in ranked])
        choice = np.where(cols < m, cols, np.where(cols < m + n, m, m + 1))
        log_w = -np.array([c for _, c in ranked])
    weights = np.exp(log_w - log_w.max())
    weights /= weights.sum()
    cells = (np.arange(n) * (m + 2) + choice).ravel()  # each hypothesis adds its weight to its n choices
    beta = np.bincount(cells, weights=np.repeat(weights, n), minlength=n * (m + 2)).reshape(n, m + 2)
    return beta[:, :-1]


def cartesian_product(options: list[np.ndarray]) -> np.ndarray:
    """(prod of lengths, len(options)): every way to pick one value from each (nonempty) array, the first varying
    slowest (as itertools.product)."""
    total = math.prod(len(o) for o in options)
    out = np.empty((total, len(options)), np.intp)
    inner = total
    for i, o in enumerate(options):
        inner //= len(o)
        out[:, i].reshape(-1, len(o) * inner)[:] = np.repeat(o, inner)  # repeated down the column
    return out


def diverged(m: np.ndarray, P: np.ndarray, image_size: tuple[float, float]) -> np.ndarray:
    """(n,) bool: the components (means m (n, 8), covariances P (n, 8, 8)) that no longer describe a box the camera
    could show, so that no track may report them: a non-finite number in the mean or the covariance, a covariance
    that is not positive definite, a box with a non-positive width or height or one over two images wide or high, or
    a corner more than one image beyond the border (the env's action space, which trackers may not import).

    Why: at the ends of the search ranges (process noise 0.1, a 0.9999 gate, survival 0.999, extract 0.2) a component
    that took a far detection learns a large velocity or growth rate (its noise, and so its gate, grows with its box)
    and runs off while its track coasts: an image beyond the border, or thousands of pixels tall, on MOT15. The
    filter's state space is boxes the camera sees (the paper's targets are those in the image), so such a component is
    a numerical runaway, not a hypothesis; with ordinary parameters none is ever flagged (outputs unchanged to the bit)."""
    w, h = image_size
    box = m[:, :4]
    finite = np.isfinite(m).all(axis=1) & np.isfinite(P).all(axis=(1, 2))
    with np.errstate(invalid="ignore"):
        ok = finite & (box[:, 0] >= -w) & (box[:, 0] <= 2 * w) & (box[:, 1] >= -h) & (box[:, 1] <= 2 * h)
        ok &= (box[:, 2] > 0) & (box[:, 2] <= 2 * w) & (box[:, 3] > 0) & (box[:, 3] <= 2 * h)
    ok[ok] = _positive_definite(P[ok])
    return ~ok


def _positive_definite(P: np.ndarray) -> np.ndarray:
    """(n,) bool: whether each finite symmetric (n, d, d) matrix is positive definite, by Cholesky (its lower
    triangle): all at once, and one by one only when one of them fails."""
    try:
        np.linalg.cholesky(P)
        return np.ones(len(P), bool)
    except np.linalg.LinAlgError:
        out = np.ones(len(P), bool)
        for i, one in enumerate(P):
            try:
                np.linalg.cholesky(one)
            except np.linalg.LinAlgError:
                out[i] = False
        return out


def _members(track_group: np.ndarray, meas_group: np.ndarray):
    """(tracks, measurements) of each group numbered >= 0 in `track_group`, in increasing group order, both sorted;
    one sort instead of two scans per group."""
    tracks, meas = np.argsort(track_group, kind="stable"), np.argsort(meas_group, kind="stable")
    groups = np.unique(track_group[track_group >= 0])
    edges = np.stack([groups, groups + 1])  # each group's first and one-past-last position once sorted
    t_bounds, m_bounds = np.searchsorted(track_group[tracks], edges), np.searchsorted(meas_group[meas], edges)
    return [(tracks[a:b], meas[c:d]) for a, b, c, d in zip(*t_bounds.tolist(), *m_bounds.tolist())]


class _Mixture:
    """Every track's Bernoulli (existence r, label) and Gaussian mixture components, sorted by track."""

    def __init__(self):
        self.r, self.label = np.zeros(0), np.zeros(0, np.int64)
        self.track, self.w = np.zeros(0, np.intp), np.zeros(0)
        self.m, self.P = np.zeros((0, gm.DIM)), np.zeros((0, gm.DIM, gm.DIM))

    def add(self, r: np.ndarray, labels: np.ndarray, m: np.ndarray, P: np.ndarray) -> None:
        """New tracks, one component each."""
        start = len(self.r)
        self.r, self.label = np.r_[self.r, r], np.r_[self.label, labels]
        self.track = np.r_[self.track, start + np.arange(len(r))]
        self.w, self.m, self.P = np.r_[self.w, np.ones(len(r))], np.r_[self.m, m], np.concatenate([self.P, P])

    def replace(self, r, track, w, m, P, keep_tracks: np.ndarray, max_components: int, prune: float) -> None:
        """New existence per track and new components; drop tracks not in `keep_tracks` and, per track, components
        under `prune` of its weight beyond the heaviest `max_components`; weights renormalised."""
        new_index = np.full(len(r), -1)
        new_index[keep_tracks] = np.arange(len(keep_tracks))
        track = new_index[track]
        ok = (track >= 0) & (w > 0)
        track, w, m, P = track[ok], w[ok], m[ok], P[ok]
        order = np.lexsort((-w, track))
        track, w, m, P = track[order], w[order], m[order], P[order]
        first = np.searchsorted(track, track)
        total = np.bincount(track, w, minlength=len(keep_tracks))
        keep = (np.arange(len(track)) - first < max_components) & (w >= prune * total[track])
        track, w, m, P = track[keep], w[keep], m[keep], P[keep]
        w = w / np.bincount(track, w, minlength=len(keep_tracks))[track]
        self.r, self.label = r[keep_tracks], self.label[keep_tracks]
        self.track, self.w, self.m, self.P = track, w, m, P

    def best(self) -> np.ndarray:
        """Index of each track's heaviest component (components are sorted by track, heaviest first)."""
        return np.searchsorted(self.track, np.arange(len(self.r)))


class LabelledMultiBernoulli(Tracker):
    """Labelled multi-Bernoulli filter (Reuter, Vo, Vo, Dietmayer 2014) as Jiang and Yang use it. Each track is a
    Bernoulli with existence probability r and a Gaussian mixture over (x, y, w, h, vx, vy, vw, vh). Prediction
    scales r by the survival probability; tracks and detections are gated (chi-square, `gate`) and split into
    independent groups; each group is updated as a delta-GLMB whose `hypotheses` best association hypotheses come
    from Murty's algorithm, then turned back into an LMB. Detections the tracks do not explain give birth at the
    next frame with r_B = birth_max x confidence x (1 - probability the detection was associated), so a confident
    unexplained detection starts a likely track and a doubtful one an unlikely track (sec. 4.2.1): low-confidence
    detections stay in the filter. birth=fixed instead places `fixed_births` newborn components along the image
    borders every frame (the traditional model). Tracks with r > `extract` are reported (coast=false: only those
    that took a measurement this frame, an ablation of coasting), tracks under `prune` are dropped, and each keeps
    at most `max_components` components; a component that diverged (`diverged`: not finite, not positive definite, a box
    beyond the action space) is dropped. use_low_confidence=false first drops detections under `low_confidence`
    (the paper's Ours_2). Clutter is uniform over the image for x, y and over
    [0, W/4] x [0, H/2] for w, h, at `clutter_rate` per frame.
    Re-identification (sec. 3, 4.4; reid=false turns it off): every `pool_every` frames a reported track whose
    most likely measurement has confidence >= `reid_confidence` puts that detection's LOMO feature (XQDA-embedded)
    with its label in a FIFO pool of `pool_per_target` x (targets of the first frame) entries; a track reported
    for the first time takes the label of the nearest pooled feature within `reid_threshold` whose label is not
    in use. Re-identification reads the video frame; its XQDA metric is the shipped one, or the file `reid_metric`
    that `mtt-sim learn-reid` wrote."""

    name = "lmb"
    description = "Labelled multi-Bernoulli filter, Murty-ranked hypotheses, confidence-driven birth, re-id " \
                  "(Jiang and Yang)"
    parameters = {
        **gm.MODEL_PARAMETERS,  # the model gmphd shares, with where a tuner looks
        "hypotheses": Param(15, "[1, inf)", "best association hypotheses per group (Murty)"),
        "birth": Param("adaptive", ("adaptive", "fixed"), "adaptive: births from unexplained detections by "
                                                          "confidence (the paper); fixed: along the borders"),
        "birth_rule": Param("confidence", ("confidence", "reuter", "reuter_confidence"),
                            "adaptive birth's r_B: confidence: birth_max x confidence x (1 - r_U) (ours); reuter: "
                            "min(birth_max, birth_rate (1 - r_U) / sum of (1 - r_U)) (Reuter et al. 2014, eq. 75); "
                            "reuter_confidence: that times the confidence. r_U: the probability the detection was "
                            "associated"),
        "birth_rate": Param(1.0, "(0, inf)", "lambda_B of birth_rule=reuter: expected newborn targets a frame"),
        "birth_max": Param(0.6, "(0, 1)", "largest newborn existence probability (a fully confident, unexplained "
                                          "detection)", (0.1, 0.95)),
        "fixed_births": Param(16, "[1, inf)", "newborn components a frame with birth=fixed"),
        "fixed_birth_r": Param(0.03, "(0, 1)", "their existence probability"),
        "extract": Param(0.5, "(0, 1)", "least existence probability of a reported track", (0.2, 0.9)),
        "coast": Param(True, None, "report tracks through frames they are missed; false (an ablation, not the "
                                   "paper): only tracks that took a measurement this frame"),
        "prune": Param(1e-3, "[0, 1)", "tracks less likely than this are dropped"),
        "max_components": Param(4, "[1, inf)", "most mixture components per track"),
        "use_low_confidence": Param(True, None, "keep detections under low_confidence (false: the paper's Ours_2 "
                                                "drops them)"),
        "low_confidence": Param(0.5, None, "the confidence that use_low_confidence=false cuts at"),
        "reid": Param(True, None, "re-identification from a pool of LOMO features (reads the frame)"),
        "cmc": Param("none", METHODS, "camera-motion compensation from the frame (beyond the paper; see "
                                      "parts/camera_motion.py): the predictions and last frame's births moved with "
                                      "the image"),
        "reid_confidence": Param(0.7, None, "least confidence of a detection whose feature enters the pool",
                                 (0.3, 0.95), needs={"reid": True}),
        "reid_threshold": Param(5.0, "(0, inf)", "largest XQDA distance of a re-identification", (1.0, 25.0, "log"),
                                needs={"reid": True}),
        "pool_per_target": Param(10, "[1, inf)", "pooled features per target of the first frame"),
        "pool_every": Param(10, "[1, inf)", "frames between pool updates"),
        "reid_metric": Param("", None, "an XQDA metric file from mtt-sim learn-reid (empty: the shipped one)")}

    @property
    def needs_frame(self) -> bool:
        return bool(self.params["reid"]) or self.params["cmc"] != "none"

    def __init__(self, **params):
        super().__init__(**params)
        try:
            self.metric = reid.Metric.from_file(self.params["reid_metric"]) if self.params["reid"] else None
        except ValueError as err:
            raise ValueError(f"tracker 'lmb': parameter reid_metric={self.params['reid_metric']!r}: {err}") from None

    def reset(self, info=None):
        p = self.params
        size = (info or {}).get("image_size")
        if size is None or min(size) <= 0:
            raise ValueError("lmb needs the image size (clutter density, border births): pass env.reset's info")
        w, h = (float(v) for v in size)
        self.image_size = (w, h)
        self.log_clutter_density = np.log(p["clutter_rate"] / (w * h * (w / 4) * (h / 2)))
        self.noise = gm.BoxNoise(p["measurement_noise"], p["process_noise"])
        self.tracks = _Mixture()
        self.pending = (np.zeros((0, 4)), np.zeros(0))  # births for the next frame: boxes, r_B
        self.next_label, self.frame = 1, 0
        self.camera = CameraMotion(p["cmc"])
        self.pool = None                      # made at the first frame, sized by its target count
        self.reported: set[int] = set()

    def _labels(self, n: int) -> np.ndarray:
        out = np.arange(self.next_label, self.next_label + n)
        self.next_label += n
        return out

    def _births(self, dets: np.ndarray) -> None:
        """Add this frame's newborn tracks: last frame's unexplained detections, or the fixed border model."""
        p, t = self.params, self.tracks
        if p["birth"] == "fixed":
            boxes, r = self._fixed_birth_boxes(dets), np.full(p["fixed_births"], p["fixed_birth_r"])
            m, P = self.noise.birth(boxes)
            P[:, 0, 0] = P[:, 1, 1] = (max(self.image_size) / p["fixed_births"]) ** 2  # anywhere along its border piece
        else:
            boxes, r = self.pending
            m, P = self.noise.birth(boxes)
        t.add(r, self._labels(len(r)), m, P)

    def _birth_existence(self, unexplained: np.ndarray, conf: np.ndarray) -> np.ndarray:
        """r_B of the newborn track each detection gives, from 1 - r_U (how unexplained it is) and its confidence."""
        p = self.params
        if p["birth_rule"] == "confidence":
            return p["birth_max"] * conf * unexplained
        share = np.minimum(p["birth_max"], p["birth_rate"] * unexplained / max(unexplained.sum(), EPS))
        return share * conf if p["birth_rule"] == "reuter_confidence" else share

    def _fixed_birth_boxes(self, dets: np.ndarray) -> np.ndarray:
        """`fixed_births` boxes spread evenly around the image border, sized like this frame's median detection."""
        w, h = self.image_size
        bw, bh = np.median(dets[:, 2:4], axis=0) if len(dets) else (w / 20, h / 10)
        s = np.linspace(0, 2 * (w + h), self.params["fixed_births"], endpoint=False)
        x = np.select([s < w, s < w + h, s < 2 * w + h], [s, w, 2 * w + h - s], 0.0)
        y = np.select([s < w, s < w + h, s < 2 * w + h], [0.0, s - w, h], 2 * (w + h) - s)
        return np.stack([np.clip(x - bw / 2, 0, w - bw), np.clip(y - bh / 2, 0, h - bh), np.full_like(s, bw),
                         np.full_like(s, bh)], axis=1)

    def update(self, obs) -> Tracks:
        p, t = self.params, self.tracks
        dets = detections(obs)
        if not p["use_low_confidence"]:
            dets = dets[dets[:, 4] >= p["low_confidence"]]
        z, conf = dets[:, :4], dets[:, 4]
        self.frame += 1
        t.r = t.r * p["survival"]
        t.m, t.P = gm.predict(t.m, t.P, self.noise)
        if p["cmc"] != "none":
            warp = self.camera.estimate(frame_of(obs), z)
            t.m, t.P = warp_centres(t.m, t.P, warp, "corner_size")
            self.pending = (warp_boxes(self.pending[0], warp), self.pending[1])
        self._births(dets)

        inn = gm.Innovation.of(t.m, t.P, self.noise)
        d2 = inn.distance2(z, chi2_gate(gm.MEAS, p["gate"]))
        gated_c = np.isfinite(d2)
        log_l = np.where(gated_c, np.log(t.w)[:, None] + inn.log_likelihood(d2), -np.inf)   # (C, M)
        n_tracks, n_meas = len(t.r), len(z)
        log_q = np.full((n_tracks, n_meas), -np.inf)                                       # log q_i(z_j) per track
        if len(t.track) and n_meas:  # log-sum-exp of each track's components
            peak = np.maximum.reduceat(log_l, t.best(), axis=0)
            safe = np.where(np.isfinite(peak), peak, 0.0)
            with np.errstate(divide="ignore"):
                log_q = safe + np.log(np.add.reduceat(np.exp(log_l - safe[t.track]), t.best(), axis=0))
        gated = np.isfinite(log_q)
        beta = self._association(gated, log_q - self.log_clutter_density)
        r_new = beta.sum(axis=1)

        # posterior mixtures: each component corrected by each measurement its track may have taken, plus missed
        c, j = np.nonzero(gated_c & (beta[t.track, :n_meas] > 0))
        w_det = np.exp(log_l[c, j] - log_q[t.track[c], j]) * beta[t.track[c], j]
        miss = beta[t.track, n_meas]
        track = np.r_[t.track[c], t.track]
        weights = np.r_[w_det, t.w * miss] / np.maximum(r_new[track], EPS)
        means = np.r_[inn.corrected_means(t.m, z, c, j), t.m]
        covs = np.concatenate([inn.P[c], t.P])
        # Diverged components (see `diverged`) are dropped, and a track left without a component with them; a weight
        # of 0 makes `replace` drop a component, and nothing else changes where none has diverged.
        broken = diverged(means, covs, self.image_size)
        weights = np.where(broken, 0.0, weights)
        alive = np.bincount(track[weights > 0], minlength=n_tracks) > 0
        keep = np.flatnonzero((r_new > p["prune"]) & alive)
        t.replace(r_new, track, weights, means, covs, keep, p["max_components"], p["prune"])

        associated = beta[:, :n_meas].sum(axis=0) if n_tracks else np.zeros(n_meas)
        r_birth = self._birth_existence(np.clip(1 - associated, 0, 1), conf)
        fresh = r_birth > p["prune"]
        self.pending = (z[fresh], r_birth[fresh])
        beta = beta[keep]
        if self.frame == 1 and p["birth"] == "adaptive":
            beta = self._first_tracks(z, r_birth)
        likely, held = self._likeliest_measurements(beta, len(dets))
        report = t.r > p["extract"]
        if not p["coast"]:
            report &= held
        if self.metric is not None:
            self._reidentify(frame_of(obs), report, likely, held, dets)
        best = t.best()[report]
        return Tracks.of(t.label[report], t.m[best, :4], t.r[report])

    def _first_tracks(self, z: np.ndarray, r: np.ndarray) -> np.ndarray:
        """Sec. 4.2.1: at k = 1 there are no tracks yet, and every detection becomes one, with existence r_B. They
        are born after the update, so the detection that bore a track does not update it too (which raised a
        0.1-confidence box to r = 0.995). Returns beta for them: each took its own detection."""
        m, P = self.noise.birth(z)
        self.tracks.add(r, self._labels(len(z)), m, P)
        self.pending = (np.zeros((0, 4)), np.zeros(0))
        return np.concatenate([np.diag(r), np.zeros((len(z), 1))], axis=1)

    def _likeliest_measurements(self, beta: np.ndarray, n_meas: int) -> tuple[np.ndarray, np.ndarray]:
        """Each track's likeliest measurement this frame, and whether it holds more than half the track's
        existence (the track took it rather than being missed or taking another)."""
        r = self.tracks.r
        if not n_meas:
            return np.zeros(len(r), int), np.zeros(len(r), bool)
        likely = np.argmax(beta[:, :n_meas], axis=1)
        return likely, beta[np.arange(len(r)), likely] > 0.5 * r

    def _reidentify(self, frame: np.ndarray, report: np.ndarray, likely: np.ndarray, held: np.ndarray,
                    dets: np.ndarray) -> None:
        """Relabel tracks reported for the first time from the pool; then pool confident associated detections."""
        p, t = self.params, self.tracks
        n_meas = len(dets)
        if self.pool is None:  # sec. 4.4: tp = tnum x T, T the targets detected in the first frame (not fixed
            self.pool = reid.FeaturePool(p["pool_per_target"] * max(1, n_meas))  # birth's border components)
        new = np.flatnonzero(report & ~np.isin(t.label, list(self.reported)))
        if len(new) and self.frame > 1:
            boxes = np.where(held[new, None], dets[likely[new], :4] if n_meas else 0, t.m[t.best()[new], :4])
            found = self.pool.match(self.metric, self._embed(frame, boxes), set(t.label.tolist()), p["reid_threshold"])
            t.label[new[found > 0]] = found[found > 0]
        self.reported.update(t.label[report].tolist())
        due = report & held & ((t.label + self.frame) % p["pool_every"] == 0)
        due &= dets[likely, 4] >= p["reid_confidence"] if n_meas else False
        rows = np.flatnonzero(due)
        if len(rows):
            self.pool.add(self._embed(frame, dets[likely[rows], :4]), t.label[rows])

    def _embed(self, frame: np.ndarray, boxes: np.ndarray) -> np.ndarray:
        return self.metric.embed(reid.lomo(reid.crops(frame, boxes)))

    def _association(self, gated: np.ndarray, log_q: np.ndarray) -> np.ndarray:
        """beta (tracks, measurements + 1) for every group. Every track alone in its group (with no measurement in
        its gate, or none another track shares) and with few options gets all its hypotheses in closed form, all
        such tracks at once; the other groups go through `group_update`."""
        p, t = self.params, self.tracks
        n, m = gated.shape
        beta = np.zeros((n, m + 1))
        if not n:
            return beta
        pd, log_r = p["detection"], np.log(np.maximum(t.r, EPS))
        track_group, meas_group = clusters(gated)
        alone = (np.bincount(track_group)[track_group] == 1) & (gated.sum(axis=1) + 2 <= p["hypotheses"])
        table = factor_table(log_r[alone], log_q[alone], pd)
        w = np.exp(table - table.max(axis=1, keepdims=True))
        beta[alone] = (w / w.sum(axis=1, keepdims=True))[:, :-1]
        for rows, cols in _members(np.where(alone, -1, track_group), meas_group):
            b = group_update(log_r[rows], log_q[rows][:, cols], pd, p["hypotheses"])
            beta[rows[:, None], cols] = b[:, :-1]
            beta[rows, m] = b[:, -1]
        return beta

    def debug(self) -> list[dict]:
        """Each track's existence probability as a bar beside its box and the covariance ellipse of its position
        (2 sigma): in the track's colour once it is reported (r above extract), grey before."""
        t = self.tracks
        out = []
        for k in t.best()[t.r > self.params["prune"] * 10]:
            i = t.track[k]
            x, y, w, h = t.m[k, :4]
            style = {"id": int(t.label[i])} if t.r[i] > self.params["extract"] else {"color": (160, 160, 160)}
            out.append(covariance_ellipse((x + w / 2, y + h / 2), t.P[k, :2, :2], 4.0, **style))
            out.append({"kind": "bar", "box": (x, y, w, h), "value": float(t.r[i]), **style})
        return out
