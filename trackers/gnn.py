"""Global nearest neighbour: Kalman-filtered box centres, chi-square gating, one Hungarian assignment per frame."""

from __future__ import annotations

import numpy as np

from .base import Param, Tracker, Tracks, covariance_ellipse, detections
from .parts.assignment import assign, chi2_gate
from .parts.kalman import KalmanBank, point_model
from .parts.track_table import CONFIRMED, TENTATIVE, TrackTable


class Gnn(Tracker):
    """Each track filters its box centre with a constant-velocity Kalman filter; detections inside the
    chi-square gate (gate_probability, 2 degrees of freedom) are assigned by minimum total squared Mahalanobis
    distance; the box size is the last associated detection's. A new track is tentative until min_hits hits
    and deleted at its first miss; a confirmed one is deleted after max_age misses. Reported: confirmed tracks,
    while matched (and while coasting if coast=true). The hard single-hypothesis association that the JPDA paper
    contrasts with JPDA."""

    name = "gnn"
    description = "Global nearest neighbour: Kalman centres, chi-square gating, Hungarian on Mahalanobis distance"
    parameters = {
        "gate_probability": Param(0.99, "(0, 1)", "probability that the gate holds a target's own measurement",
                                  (0.9, 0.9999)),
        "min_hits": Param(3, "[0, inf)", "hits before a track is reported", (1, 8)),
        "max_age": Param(5, "[0, inf)", "misses before a confirmed track ends", (1, 60, "log")),
        "accel_sigma": Param(0.5, "[0, inf)", "white acceleration, px/frame^2", (0.05, 5.0, "log")),
        "meas_sigma": Param(2.0, "(0, inf)", "detection centre noise, px", (1.0, 50.0, "log")),
        "coast": Param(False, None, "report confirmed tracks through their misses", (False, True)),
        "min_confidence": Param(0.0, None, "detections below this confidence are dropped", (0.0, 0.9))}

    def reset(self, info=None):
        p = self.params
        self.tracks = TrackTable(KalmanBank(point_model(p["accel_sigma"], p["meas_sigma"])), state=np.int8, score=np.float64,
                                 last_box=(np.float64, (4,)))  # the last associated detection's box and score
        self.gate = chi2_gate(2, p["gate_probability"])
        self._gates = (np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros((0, 2, 2)))

    def debug(self) -> list[dict]:
        """The validation gates of the last association: ellipses d^2 = gate around each predicted centre."""
        return [covariance_ellipse(centre, S, self.gate, id=int(i)) for i, centre, S in zip(*self._gates)]

    def update(self, obs) -> Tracks:
        p, tracks = self.params, self.tracks
        dets = detections(obs)
        dets = dets[dets[:, 4] >= p["min_confidence"]]
        centres = dets[:, :2] + dets[:, 2:4] / 2
        tracks.kf.predict()
        tracks.tick()
        cost = tracks.kf.mahalanobis(centres) if len(tracks) else np.zeros((0, len(dets)))
        self._gates = (tracks.ids.copy(), tracks.kf.measurement(), tracks.kf.innovation_covariance())
        matches, _, new = assign(cost, self.gate)
        rows, cols = matches[:, 0], matches[:, 1]
        tracks.matched(rows)
        tracks.last_box[rows], tracks.score[rows] = dets[cols, :4], dets[cols, 4]
        tracks.kf.update(rows, centres[cols])
        tracks.state[(tracks.state == TENTATIVE) & (tracks.hits >= p["min_hits"])] = CONFIRMED
        tracks.keep(np.where(tracks.state == TENTATIVE, tracks.misses == 0, tracks.misses <= p["max_age"]))
        tracks.add(len(new), centres[new], hits=1, streak=1, state=CONFIRMED if p["min_hits"] <= 1 else TENTATIVE,
                   score=dets[new, 4], last_box=dets[new, :4])
        report = (tracks.state == CONFIRMED) & ((tracks.misses == 0) | p["coast"])
        size = tracks.last_box[report, 2:]
        return Tracks.of(tracks.ids[report], np.c_[tracks.kf.x[report, :2] - size / 2, size], tracks.score[report])
