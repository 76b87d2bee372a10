"""Wan, Wang and Yuan (2011): JPDA with Murty's K best joint events, for video multi-target tracking.

The association core. A joint event assigns each target at most one measurement and each measurement
at most one target (the rest are clutter); in the standard parametric form of the paper's eq. 8,
P(event) is proportional to the product over associated pairs (t, j) of P_D g_tj / lambda and over
unassociated targets of (1 - P_D), with g_tj the Gaussian innovation likelihood and lambda the clutter
density. Eq. 9 sums these into beta. Exactly, every joint event is enumerated (exponential in the
cluster size); the paper instead takes the K most probable events, found by Murty's algorithm on the
assignment problem whose cost is -log of those factors, with one dummy "missed" column per target.
"""

from __future__ import annotations

import itertools

import numpy as np

from .base import Param, Tracker, Tracks, covariance_ellipse, detections
from .parts.assignment import chi2_gate, clusters, murty
from .parts.kalman import KalmanBank, point_model
from .parts.track_table import CONFIRMED, TrackTable


ENUMERATE_UP_TO = 256  # clusters with at most this many joint events (an upper bound) are enumerated


def _factors(g, pd, clutter_density) -> tuple[np.ndarray, np.ndarray]:
    """Per-pair detection factors P_D g / lambda (n, m) and per-target miss factors 1 - P_D (n,), validated."""
    g = np.asarray(g, float)
    if g.ndim != 2 or not np.isfinite(g).all() or (g < 0).any():
        raise ValueError(f"g must be a finite, non-negative (targets, measurements) matrix, got shape {g.shape}")
    pd = np.broadcast_to(np.asarray(pd, float), (g.shape[0],))
    if ((pd < 0) | (pd > 1)).any():
        raise ValueError(f"pd must lie in [0, 1], got {pd.tolist()}")
    if not clutter_density > 0:
        raise ValueError(f"clutter_density must be positive, got {clutter_density!r}")
    return pd[:, None] * g / clutter_density, 1.0 - pd


def _joint_events(w: np.ndarray, miss: np.ndarray):
    """Every joint event with a nonzero weight, one at a time (depth first, target 0's choice varying slowest, a miss
    before the measurements): (measurement of each target or -1, weight)."""
    n = w.shape[0]
    options = [np.flatnonzero(row).tolist() for row in w]

    def extend(t: int, chosen: list[int], used: set[int], weight: float):
        if t == n:
            yield list(chosen), weight
            return
        if miss[t] > 0:
            yield from extend(t + 1, chosen + [-1], used, weight * miss[t])
        for j in options[t]:
            if j not in used:
                yield from extend(t + 1, chosen + [j], used | {j}, weight * w[t, j])

    return extend(0, [], set(), 1.0)


def _all_events(w: np.ndarray, miss: np.ndarray, limit: int | None = None) -> list[tuple[list[int], float]] | None:
    """Every joint event with a nonzero weight: (measurement of each target or -1, weight); None if there are more
    than `limit` (the listing stops at the first one past it, so a cluster of millions costs `limit` steps)."""
    events = list(itertools.islice(_joint_events(w, miss), None if limit is None else limit + 1))
    return None if limit is not None and len(events) > limit else events


def _best_events(w: np.ndarray, miss: np.ndarray, k: int) -> list[tuple[list[int], float]]:
    """The k most probable joint events (Murty on -log factors), weights relative to the best."""
    n, m = w.shape
    with np.errstate(divide="ignore"):
        cost = np.full((n, m + n), np.inf)
        cost[:, :m] = -np.log(w)
        cost[np.arange(n), m + np.arange(n)] = -np.log(miss)
    best = murty(cost, k)
    if not best:
        return []
    low = best[0][1]
    return [(np.where(cols < m, cols, -1).tolist(), float(np.exp(low - total))) for cols, total in best]


def association_probabilities(g, pd, clutter_density: float, k: int | None = None,
                             budget: int | None = None) -> np.ndarray:
    """beta (n_targets, m + 1): beta[t, 0] the probability that no measurement is target t's, beta[t, j + 1] that
    measurement j is. g (n, m) Gaussian likelihoods, 0 where gated out; pd scalar or per target; k=None enumerates
    every joint event, an int uses the k best from Murty (renormalised). budget (with k=None): the most joint events
    enumerated; a cluster with more takes its `budget` most probable instead (Murty: the paper's K-best
    approximation with K = budget), so its cost is bounded however wide the gates."""
    w, miss = _factors(g, pd, clutter_density)
    n, m = w.shape
    if k is not None and (not isinstance(k, (int, np.integer)) or k < 1):
        raise ValueError(f"k must be None (exact) or a positive integer, got {k!r}")
    if budget is not None and (not isinstance(budget, (int, np.integer)) or budget < 1):
        raise ValueError(f"budget must be None (no limit) or a positive integer, got {budget!r}")
    # Few joint events (bounded by the product of each target's options): enumerating them all and keeping the k
    # heaviest gives the same k best events as Murty, far cheaper than its subproblems. Otherwise Murty.
    few = np.prod(1.0 + (w > 0).sum(axis=1)) <= ENUMERATE_UP_TO
    if k is None:
        events = _all_events(w, miss, budget)
        if events is None:  # more joint events than the budget: the budget's best
            k = budget
    if k is not None:
        events = sorted(_all_events(w, miss), key=lambda e: -e[1])[: int(k)] if few else _best_events(w, miss, int(k))
    total = sum(weight for _, weight in events)
    if not total > 0:
        raise ValueError("no joint event has a nonzero probability (pd = 1 and a target without a gated measurement?)")
    # each event adds its weight to its n (target, choice) cells, event after event (as a loop would, to the bit)
    chosen = np.array([c for c, _ in events], np.intp).reshape(len(events), n)
    cells = (np.arange(n) * (m + 1) + chosen + 1).ravel()
    weights = np.repeat(np.array([weight for _, weight in events], float), n)
    beta = np.bincount(cells, weights=weights, minlength=n * (m + 1)).reshape(n, m + 1)
    return beta / total


# ------------------------------------------------------------------ the tracker

NORMAL, NEW, VANISHED, OCCLUDED, SPLIT, REVIVED = "normal", "new", "vanished", "occluded", "split", "revived"
SEPARATED = "separated"
TAGS = {NORMAL: "norm", NEW: "new", VANISHED: "miss", OCCLUDED: "occl", SPLIT: "split", REVIVED: "back",
        SEPARATED: "sep"}  # the situations as short tags on video


def _most_probable(beta: np.ndarray) -> np.ndarray:
    """Each target's most probable measurement (column of beta past the first; 0 when there is none)."""
    return np.argmax(beta[:, 1:], axis=1) if beta.shape[1] > 1 else np.zeros(len(beta), int)


def situations(beta_prime: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Each target's motion situation from beta' (measurements x targets), and the measurements left unexplained.

    Section 5 of the paper: a column with one positive entry whose row has no other is NORMAL; an all-zero column is
    VANISHED; a column with several positive entries is SPLIT (fragments; the JPDA update stands); a target whose
    only positive entry lies in a row shared with other such targets is OCCLUDED (merged into one blob: the paper's
    "row with several positive entries", read as Fig. 5(c)'s merge so that targets whose gates merely overlap keep
    the JPDA update). An all-zero row is a NEW candidate.
    """
    positive = beta_prime > 0
    per_col, per_row = positive.sum(axis=0), positive.sum(axis=1)
    first = np.argmax(positive, axis=0) if len(positive) else np.zeros(positive.shape[1], int)
    only = np.where(per_col == 1, first, -1)  # a target's single measurement
    sharing = np.bincount(only[only >= 0], minlength=len(beta_prime))
    shared = np.where(only >= 0, sharing[np.maximum(only, 0)] if len(sharing) else 0, 0) > 1
    # NORMAL includes a single measurement shared with targets that have others too: plain JPDA
    kind = np.select([per_col == 0, per_col > 1, shared], [VANISHED, SPLIT, OCCLUDED], NORMAL)
    return kind.tolist(), np.flatnonzero(per_row == 0)


class Jpda(Tracker):
    """Wan, Wang and Yuan (2011): each target's box centre is Kalman-filtered with a constant-velocity model;
    measurements (detection centres) within the gate d^2 <= chi2(gate_probability, 2) form the validation matrix; targets sharing
    measurements are clustered; in each cluster the joint-event probabilities (P_D, clutter density) give beta from
    the K most probable events found by Murty (K = targets + measurements, as in the paper) and the JPDA update
    combines all gated measurements. beta' then classifies each target (normal, new, vanished, occluded, split):
    occluded targets jump to the shared measurement with zero velocity; a target vanished for vanish_frames frames is
    ended but can be revived by a new measurement within revive_frames; other unexplained measurements start
    targets at rest. Boxes take the size of the most probable measurement of a normal or new target, else their
    last size. situations=false drops the occlusion correction, the separation, the duplicate rule and the revival
    (the paper's traditional JPDA, with births and deaths); k=0 means the paper's K.

    Gaps the paper leaves open, filled here: merged targets coming apart take one measurement each from the best
    joint event; duplicates (a young target, or one that shares a blob for merge_frames frames) are dropped.

    Track management that departs from the paper, each a parameter whose other value is the paper's (the paper's reports
    every newborn target and every member of a blob: thousands of false positives on a crowded scene):
    min_hits=3 reports a target once it has had a measurement 3 frames in a row, and from then on (1: at once);
    coast=true reports a confirmed target through its misses at its prediction until it vanishes, as Stone Soup
    does (false: only in frames with a measurement); early_duplicates=true drops a newborn duplicate sharing a blob
    with its elder before the situations are read, so the elder is not snapped to the blob (false: afterwards);
    blob_report=size reports, of the targets merged into one blob, only as many as its box holds people: the
    blob's area over the mean of its members' own last areas, rounded, at least one; the eldest are reported and
    the rest tracked unseen until the blob separates (all: every member). This reads section 5's merge as the
    paper draws it: merged targets share one state at the blob, and only the best joint event at separation says
    who leaves as whom, so a blob is evidence of the people it can hold, not of every track that touched it.
    merge_needs_overlap=true classes targets sharing one measurement as occluded only where their predicted boxes
    overlap: apart, one measurement for two is a missed detection and the JPDA update stands (false: the paper's,
    any shared sole measurement is a merge). Not departures, but choices the paper does not make:
    occlusion_velocity=keep keeps an occluded target's velocity (zero: the paper's); occlusion_covariance=full
    restarts the velocity's covariance with the zeroed velocity (position: only the position's, the default).
    The paper's track management is
    min_hits=1,coast=false,early_duplicates=false,blob_report=all,merge_needs_overlap=false.

    Units: pixels and frames. meas_sigma is the standard deviation of a detection centre (px), accel_sigma that of
    a white acceleration per frame (px/frame^2; its velocity variance per frame is accel_sigma^2, so Stone Soup's
    ConstantVelocity(q) is accel_sigma = sqrt(q)), speed_sigma0 a new target's velocity spread (px/frame);
    clutter_density is false detections per px^2 per frame, pd the detection probability."""

    name = "jpda"
    description = "JPDA with Murty's K best joint events and video motion situations (Wan, Wang and Yuan 2011)"
    parameters = {
        "pd": Param(0.9, "(0, 1)", "detection probability P_D", (0.4, 0.98)),
        "clutter_density": Param(1e-5, "(0, inf)", "clutter density lambda: false detections per px^2 per frame",
                                 (1e-6, 1e-4, "log")),
        "gate_probability": Param(0.99, "(0, 1)", "probability that the gate holds a target's own measurement",
                                  (0.9, 0.9999)),
        "k": Param(0, "[0, inf)", "joint events per cluster; 0: the paper's K = targets + measurements"),
        "vanish_frames": Param(3, "[1, inf)", "frames in a row without a measurement that end a target",
                               (1, 30, "log")),
        "revive_frames": Param(5, "[0, inf)", "frames an ended target can still be revived", (1, 60, "log"),
                               needs={"situations": True}),
        "accel_sigma": Param(0.5, "[0, inf)", "white acceleration, px/frame^2 (Stone Soup ConstantVelocity(q): "
                                              "sqrt(q))", (0.05, 5.0, "log")),
        "meas_sigma": Param(4.0, "(0, inf)", "detection centre noise, px", (1.0, 50.0, "log")),
        "min_confidence": Param(0.0, None, "detections below this confidence are dropped", (0.0, 0.9)),
        "situations": Param(True, None, "the paper's motion situations (false: traditional JPDA)"),
        "occlusion_velocity": Param("zero", ("keep", "zero"), "an occluded target's velocity (zero: the paper's)"),
        "speed_sigma0": Param(2.0, "(0, inf)", "a new target's velocity spread, px/frame", (0.2, 20.0, "log")),
        "min_hits": Param(3, "[1, inf)", "frames in a row with a measurement before a target is reported (paper: 1)",
                          (1, 8)),
        "merge_frames": Param(40, "[1, inf)", "frames in one blob after which the younger target is a duplicate",
                              (5, 200, "log"), needs={"situations": True}),
        "coast": Param(True, None, "report confirmed targets through their misses (paper: false)"),
        "early_duplicates": Param(True, None, "drop a newborn duplicate before reading the situations (paper: false)"),
        "occlusion_covariance": Param("position", ("position", "full"), "what an occluded target's covariance "
                                                                        "restarts: position, or velocity too"),
        "blob_report": Param("size", ("all", "size"),
                             "merged targets reported: as many as the blob holds (paper: all)"),
        "merge_needs_overlap": Param(True, None, "a merge needs overlapping predicted boxes (paper: false)")}

    def reset(self, info=None):
        p = self.params
        self.model = point_model(p["accel_sigma"], p["meas_sigma"], p["speed_sigma0"])
        # The targets: streak counts frames in a row with a measurement, together frames in one blob, last_box[:, 2:]
        # is the size (hits unused). Ended targets wait in a table of their own to be revived; there age counts the
        # frames since they ended.
        self.tracks = TrackTable(KalmanBank(self.model), state=np.int8, last_box=(np.float64, (4,)), together=np.int64)
        self.ended = TrackTable(KalmanBank(self.model), state=np.int8, last_box=(np.float64, (4,)))
        self.gate = chi2_gate(2, p["gate_probability"])
        self.last = {"situations": [], "beta": np.zeros((0, 1)), "gated": np.zeros((0, 0), bool),
                     "ids": np.zeros(0, np.int64), "centres": np.zeros((0, 2)), "S": np.zeros((0, 2, 2))}

    # -------------------------------------------------------------- one frame

    def update(self, obs) -> Tracks:
        p, tracks = self.params, self.tracks
        dets = detections(obs)
        dets = dets[dets[:, 4] >= p["min_confidence"]]
        z = dets[:, :2] + dets[:, 2:4] / 2
        tracks.kf.predict()
        self.ended.kf.predict()
        self.ended.tick()
        beta, gated, g = self._associate(z)
        situ, unexplained = situations(beta[:, 1:].T)
        if p["situations"] and p["early_duplicates"] and len(z) and \
                self._drop_duplicates(situ, _most_probable(beta), newborn_only=True):
            beta, gated, g = self._associate(z)  # without the newborn duplicates: the elder is not snapped
            situ, unexplained = situations(beta[:, 1:].T)
        if p["situations"] and p["merge_needs_overlap"]:
            self._apart_is_not_merged(situ, _most_probable(beta))
        if p["situations"]:
            self._separate(situ, beta, g)
        kf = tracks.kf
        self.last = {"situations": list(situ), "beta": beta, "gated": gated, "ids": tracks.ids.copy(),
                     "centres": kf.measurement(), "S": kf.innovation_covariance()}
        self._jpda_update(beta, z)
        best = _most_probable(beta)
        kind = np.array(situ, dtype=object)
        occluded = np.flatnonzero(kind == OCCLUDED) if p["situations"] else np.zeros(0, int)
        # The merged blob's centre (section 5, 4). The paper also zeroes the velocity, so merged targets share one
        # state and _separate's best joint event decides who leaves the blob as whom; occlusion_velocity=keep lets
        # each keep its own velocity instead (over 10 seeds of crossing and soccer the two do not differ
        # significantly).
        kf.x[occluded, :2] = z[best[occluded]]
        if p["occlusion_velocity"] == "zero":
            kf.x[occluded, 2:] = 0.0
            if p["occlusion_covariance"] == "full":  # a velocity set to 0 is not known: its covariance restarts too
                kf.P[occluded, 2:, 2:] = self.model.P0[2:, 2:]
        kf.P[occluded, :2, :2] = self.model.P0[:2, :2]  # a fresh position, uncorrelated with the velocity
        kf.P[occluded, :2, 2:] = kf.P[occluded, 2:, :2] = 0.0
        hidden = self._surplus(occluded, best[occluded], dets) if p["blob_report"] == "size" else occluded[:0]
        sized = np.flatnonzero((kind == NORMAL) | (kind == SEPARATED))
        tracks.last_box[sized] = dets[best[sized], :4]
        tracks.misses = np.where(kind == VANISHED, tracks.misses + 1, 0)
        tracks.streak = np.where(tracks.misses == 0, tracks.streak + 1, 0)
        own = (kind == NORMAL) | (kind == SEPARATED) | (kind == SPLIT)  # a miss says nothing either way
        tracks.together = np.where(own, 0, tracks.together + (kind == OCCLUDED))
        tracks.age += 1
        hidden_ids = tracks.ids[hidden]
        if p["situations"]:
            self._drop_duplicates(situ, best)
        tracks.move(tracks.misses >= p["vanish_frames"], self.ended, age=0)  # vanished: ended, for the revival pool
        fresh = self._revive(z, dets, unexplained) if p["situations"] else unexplained
        tracks.add(len(fresh), z[fresh], hits=1, streak=1, last_box=dets[fresh, :4])  # new targets at rest (section 5, 2)
        self.last["situations"] += [REVIVED] * (len(tracks) - len(situ) - len(fresh)) + [NEW] * len(fresh)
        tracks.state[tracks.streak >= p["min_hits"]] = CONFIRMED  # once: a confirmed target stays so through its misses
        seen = (tracks.state == CONFIRMED) & ((tracks.misses == 0) | p["coast"])
        seen[np.isin(tracks.ids, hidden_ids)] = False
        size = tracks.last_box[seen, 2:]
        return Tracks.of(tracks.ids[seen], np.c_[kf.x[seen, :2] - size / 2, size])

    def _associate(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """beta (targets, 1 + measurements) cluster by cluster, and the validation (gate) matrix."""
        p, n, m = self.params, len(self.tracks), len(z)
        beta = np.zeros((n, m + 1))
        beta[:, 0] = 1.0
        if not n or not m:
            return beta, np.zeros((n, m), bool), np.zeros((n, m))
        d2 = self.tracks.kf.mahalanobis(z)
        gated = d2 <= self.gate
        det_s = np.linalg.det(self.tracks.kf.innovation_covariance())
        g = np.where(gated, np.exp(-0.5 * d2) / (2 * np.pi * np.sqrt(det_s))[:, None], 0.0)
        t_label, z_label = clusters(gated)
        has = gated.any(axis=1)
        alone = has & (np.bincount(t_label)[t_label] == 1)  # a target alone in its cluster: its m + 1 events in closed form
        w = p["pd"] * g[alone] / p["clutter_density"]
        total = (1 - p["pd"]) + w.sum(axis=1, keepdims=True)
        beta[alone, 0], beta[alone, 1:] = (1 - p["pd"]) / total[:, 0], w / total
        for c in np.unique(t_label[has & ~alone]):
            ti, zj = np.flatnonzero(t_label == c), np.flatnonzero(z_label == c)
            b = association_probabilities(g[np.ix_(ti, zj)], p["pd"], p["clutter_density"], self._k(len(ti), len(zj)),
                                          self._budget())
            beta[ti, 0] = b[:, 0]
            beta[np.ix_(ti, zj + 1)] = b[:, 1:]
        return beta, gated, g

    def _apart_is_not_merged(self, situ: list[str], best: np.ndarray) -> None:
        """Occluded targets whose predicted boxes overlap no other target of their blob are not merged: one
        measurement for two targets apart is a missed detection, and the JPDA update stands (NORMAL)."""
        occluded = np.flatnonzero(np.array(situ, dtype=object) == OCCLUDED)
        if len(occluded) < 2:
            return
        centre, half = self.tracks.kf.x[occluded, :2], self.tracks.last_box[occluded, 2:] / 2
        apart = (np.abs(centre[:, None] - centre[None]) >= half[:, None] + half[None]).any(axis=2)
        touching = (~apart & (best[occluded][:, None] == best[occluded][None])).sum(axis=1) > 1  # itself too
        for t in occluded[~touching]:
            situ[t] = NORMAL

    def _separate(self, situ: list[str], beta: np.ndarray, g: np.ndarray) -> None:
        """Targets that shared a blob last frame and now see several measurements take one each, from the most
        probable joint event, instead of the soft JPDA mixture that would hold them together at the blob (the
        paper's split rule is meant for fragments of one target; it does not say how merged targets come apart)."""
        rows = np.flatnonzero((self.tracks.together > 0) & (np.array(situ, dtype=object) == SPLIT))
        if len(rows) < 2:
            return
        cols = np.flatnonzero(beta[rows, 1:].sum(axis=0) > 0)
        w, miss = _factors(g[np.ix_(rows, cols)], self.params["pd"], self.params["clutter_density"])
        chosen = np.asarray(_best_events(w, miss, 1)[0][0])
        beta[rows] = 0.0
        beta[rows, np.where(chosen >= 0, cols[chosen] + 1, 0)] = 1.0
        for t in rows:
            situ[t] = SEPARATED

    def _k(self, n_targets: int, n_measurements: int) -> int | None:
        """How many joint events a cluster uses: the paper's K = targets + measurements unless set."""
        return self.params["k"] or n_targets + n_measurements

    def _budget(self) -> int | None:
        """The most joint events a cluster enumerated in full may have (with k None); None: no limit."""
        return None

    def _jpda_update(self, beta: np.ndarray, z: np.ndarray) -> None:
        """Eq. 10-12 for every target at once: the beta-weighted innovation, and the covariance with its spread."""
        kf = self.tracks.kf
        if not len(kf) or not len(z):
            return
        H, R, x, P = self.model.H, self.model.R, kf.x, kf.P
        S = H @ P @ H.T + R
        K = np.linalg.solve(S, H @ P).transpose(0, 2, 1)
        nu = z[None, :, :] - (x @ H.T)[:, None, :]
        b, b0 = beta[:, 1:], beta[:, 0]
        combined = np.einsum("nm,nmi->ni", b, nu)
        spread = np.einsum("nm,nmi,nmj->nij", b, nu, nu) - combined[:, :, None] * combined[:, None, :]
        kf.x = x + np.einsum("nij,nj->ni", K, combined)
        P = P - (1 - b0)[:, None, None] * (K @ S @ K.transpose(0, 2, 1)) + K @ spread @ K.transpose(0, 2, 1)
        kf.P = (P + P.transpose(0, 2, 1)) / 2  # keep it symmetric against rounding

    def _by_blob(self, occluded: np.ndarray, blob: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Occluded targets (rows) and their blobs (measurements) ordered by blob, then eldest, then lowest id, the
        index of each blob's first, and each target's rank in its blob (0 the eldest)."""
        order = np.lexsort((self.tracks.ids[occluded], -self.tracks.age[occluded], blob))
        blob = blob[order]
        starts = np.flatnonzero(np.r_[True, blob[1:] != blob[:-1]])
        rank = np.arange(len(blob)) - np.repeat(starts, np.diff(np.r_[starts, len(blob)]))
        return occluded[order], blob, starts, rank

    def _drop_duplicates(self, situ: list[str], best: np.ndarray, newborn_only: bool = False) -> bool:
        """Targets occluded together with an older one are dropped when they are younger than vanish_frames (a
        fragment or a clutter blob beside it) or, unless newborn_only, have shared its blob for merge_frames frames
        (one object): the paper's occlusion rule would keep such duplicates at the same place for ever. Returns
        whether any was dropped."""
        occluded = np.flatnonzero(np.array(situ, dtype=object) == OCCLUDED)
        if len(occluded) < 2:
            return False
        occluded, _, _, rank = self._by_blob(occluded, best[occluded])
        p, tracks = self.params, self.tracks
        duplicate = tracks.age[occluded] < p["vanish_frames"]
        if not newborn_only:
            duplicate |= tracks.together[occluded] >= p["merge_frames"]
        dropped = duplicate & (rank > 0)  # the elder of each blob stays
        keep = np.ones(len(tracks), bool)
        keep[occluded[dropped]] = False
        tracks.keep(keep)
        return bool(dropped.any())

    def _surplus(self, occluded: np.ndarray, blob: np.ndarray, dets: np.ndarray) -> np.ndarray:
        """The occluded targets a merged blob has no room for (blob_report=size): beyond the eldest round(blob's
        area / mean of its members' own last areas), at least one."""
        if not len(occluded):
            return occluded
        occluded, blob, starts, rank = self._by_blob(occluded, blob)
        members = np.diff(np.r_[starts, len(occluded)])
        mean_area = np.add.reduceat(self.tracks.last_box[occluded, 2:].prod(axis=1), starts) / members
        room = np.maximum(1, np.floor(dets[blob[starts], 2:4].prod(axis=1) / np.maximum(mean_area, 1e-9) + 0.5))
        return occluded[rank >= np.repeat(room, members)]

    def _revive(self, z: np.ndarray, dets: np.ndarray, unexplained: np.ndarray) -> np.ndarray:
        """Unexplained measurements that associate normally (uniquely, both ways) with a recently ended target
        bring it back; the others are returned as new targets."""
        e = self.ended
        e.keep(e.age <= self.params["revive_frames"])
        if not len(unexplained) or not len(e):
            return unexplained
        gated = e.kf.mahalanobis(z[unexplained]) <= self.gate
        unique = gated & (gated.sum(axis=0) == 1)[None, :] & (gated.sum(axis=1) == 1)[:, None]
        rows, cols = np.nonzero(unique)
        e.kf.update(rows, z[unexplained[cols]])
        e.move(rows, self.tracks, misses=0, streak=1, age=self.params["vanish_frames"],
               last_box=dets[unexplained[cols], :4])
        return np.setdiff1d(unexplained, unexplained[cols])

    def debug(self) -> list[dict]:
        """The last association's gate ellipses (d^2 = gate around each predicted centre), each target's motion
        situation as text, and the validation matrix and beta as data."""
        out = []
        last = self.last
        for i, centre, S, situation in zip(last["ids"].tolist(), last["centres"], last["S"], last["situations"]):
            out.append(covariance_ellipse(centre, S, self.gate, id=i))
            out.append({"kind": "text", "xy": centre + np.array([6.0, -6.0]), "text": TAGS[situation], "id": i})
        out.append({"kind": "data", "ids": last["ids"], "validation": last["gated"], "beta": last["beta"]})
        return out


class JpdaExact(Jpda):
    """Traditional JPDA, as the paper's baseline: the same filter, but every joint event of a cluster is enumerated
    (exponential in the cluster size), within a budget: a cluster of more than max_events joint events (counted as
    they are listed, so the listing stops there) or of more than max_exact_targets targets takes its max_events most
    probable joint events instead, found by Murty's algorithm: the paper's own K-best approximation, with K = the
    budget. So wide gates or a crowd cannot stall it (max_events=5000: a cluster costs at most 5000 events, listed
    or ranked); below the budget it is exact."""

    name = "jpda_exact"
    description = "Traditional JPDA: every joint event enumerated, up to max_events a cluster (then Murty's best)"
    parameters = {
        **Jpda.parameters,
        "max_exact_targets": Param(8, "[0, 20]", "largest cluster (targets) whose joint events are all enumerated"),
        "max_events": Param(5000, "[1, inf)", "the budget: most joint events a cluster enumerates; a cluster with "
                                              "more (or over max_exact_targets targets) takes this many of its most "
                                              "probable (Murty)")}

    def _k(self, n_targets: int, n_measurements: int) -> int | None:
        return None if n_targets <= self.params["max_exact_targets"] else self.params["max_events"]

    def _budget(self) -> int | None:
        # The budget (issue 37): a 50 px meas_sigma's gates took in every detection, and listing a cluster's joint
        # events ran over 30 minutes on one sequence; past max_events the cluster gets Murty's max_events best.
        return self.params["max_events"]
