"""OC-SORT (Cao, Pang, Weng, Khirodkar, Kitani, CVPR 2023): SORT made observation-centric, as the official code
noahcao/OC_SORT (trackers/ocsort_tracker, commit bdfbc98) computes it."""

from __future__ import annotations

import numpy as np

from .base import Param, Tracker, Tracks, detections
from .parts.boxes import state_to_corners
from .parts.kalman import KalmanBank, box_model, stop_shrinking_to_nothing
from .parts.rounds import associate, rematch, without
from .parts.track_table import TrackTable

NONE = -(2**62)  # the age of an empty slot in a track's recent observations
NO_BOX = np.full(5, -1.0)  # the reference's placeholder for "no observation" (x1, y1, x2, y2, confidence)


class OcSort(Tracker):
    """SORT's Kalman boxes with three observation-centric changes. Momentum (OCM): the association cost adds to
    IoU how well each detection's direction from the track's observation delta_t frames back agrees with the
    track's own direction of motion between observations, weighted by inertia and the detection's confidence.
    Recovery (OCR): tracks and detections left over are matched a second time by IoU with the track's last
    observation instead of its prediction. Re-update (ORU): a track found again after a gap has its filter rewound
    to its first missed frame and re-run along a straight, constant-speed path between its last observation and
    the new one. Reported boxes are the matched detections themselves. Only detections over det_thresh are used;
    use_byte adds ByteTrack's second round on those between 0.1 and det_thresh (off, as in the paper's results).
    Box for box the official code with OCSort(det_thresh=0.6, max_age=30, min_hits=3, iou_threshold=0.3, delta_t=3,
    asso_func="iou", inertia=0.2, use_byte=False); its other cost functions (GIoU, DIoU, CIoU, centre distance)
    are not offered."""

    name = "ocsort"
    description = "OC-SORT (Cao et al. 2023): SORT with observation-centric momentum, recovery and re-update"
    parameters = {
        "det_thresh": Param(0.6, None, "least confidence of a detection used (strictly over)", (0.1, 0.9)),
        "max_age": Param(30, "[0, inf)", "frames a track is kept without a match", (1, 90, "log")),
        "min_hits": Param(3, "[0, inf)", "matches in a row before a track is reported (from the first frames at "
                                         "once, as the reference)", (0, 6)),
        "iou_threshold": Param(0.3, "[0, 1]", "least IoU of a match", (0.05, 0.7)),
        "delta_t": Param(3, "[1, inf)", "frames back to the observation a direction is measured from", (1, 6)),
        "inertia": Param(0.2, "[0, inf)", "weight of the direction agreement in the association cost", (0.0, 1.0)),
        "use_byte": Param(False, None, "ByteTrack's second round with detections between 0.1 and det_thresh")}

    def reset(self, info=None):
        k = self.params["delta_t"]
        self.tracks = TrackTable(
            KalmanBank(box_model()),
            last=(np.float64, (5,)),           # last observation (x1, y1, x2, y2, confidence), or NO_BOX
            recent_age=(np.int64, (k,)),       # ages of the last delta_t observations, oldest first
            recent=(np.float64, (k, 5)),       # and those observations
            velocity=(np.float64, (2,)),       # unit direction (dy, dx) between observations
            observed=bool,                     # the filter's last update had a measurement
            frozen=bool,                       # a filter state was saved at the first missed frame
            saved_x=(np.float64, (7,)), saved_P=(np.float64, (7, 7)),
            last_z=(np.float64, (4,)))         # the filter's last measurement (cx, cy, s, r), real or virtual

    def update(self, obs) -> Tracks:
        p = self.params
        dets = detections(obs)
        dets = np.concatenate([dets[:, :2], dets[:, :2] + dets[:, 2:4], dets[:, 4:]], axis=1)  # given x1, y1, x2, y2
        score = dets[:, 4]
        high = dets[score > p["det_thresh"]]
        low = dets[(score > 0.1) & (score < p["det_thresh"])]
        tracks = self.tracks
        stop_shrinking_to_nothing(tracks.kf)
        tracks.kf.predict()
        tracks.tick()
        predicted = state_to_corners(tracks.kf.x)
        defined = ~np.isnan(predicted).any(axis=1)
        tracks.keep(defined)
        predicted = predicted[defined]
        previous = self._previous_observations()

        bonus = p["inertia"] * direction_agreement(high, previous, tracks.velocity).T * high[:, 4:5]
        bonus[:, previous[:, 4] < 0] = 0.0  # no direction from a track never observed
        matched, left_dets, left_tracks = associate(high[:, :4], predicted, p["iou_threshold"], bonus)
        pairs = [(high, matched[:, 0], matched[:, 1])]
        if p["use_byte"] and len(low) and len(left_tracks):
            found = rematch(low, predicted[left_tracks], p["iou_threshold"])
            if found is not None:
                d, t = found
                pairs.append((low, d, left_tracks[t]))
                left_tracks = np.sort(left_tracks[without(len(left_tracks), t)])
        if len(left_dets) and len(left_tracks):
            found = rematch(high[left_dets], tracks.last[left_tracks], p["iou_threshold"])
            if found is not None:
                d, t = found
                pairs.append((high, left_dets[d], left_tracks[t]))
                left_dets = np.sort(left_dets[without(len(left_dets), d)])  # the reference's setdiff1d sorts
                left_tracks = np.sort(left_tracks[without(len(left_tracks), t)])
        t = np.concatenate([t for _, _, t in pairs])
        self._observe(t, np.concatenate([source[d] for source, d, _ in pairs]), previous[t])
        self._miss(left_tracks)
        self._start(high[left_dets])

        report = (tracks.misses < 1) & ((tracks.streak >= p["min_hits"]) | (tracks.frame <= p["min_hits"]))
        box = np.where((tracks.last.sum(axis=1) < 0)[:, None], state_to_corners(tracks.kf.x), tracks.last[:, :4])
        box = box[report]
        out = Tracks.of(tracks.ids[report], np.concatenate([box[:, :2], box[:, 2:] - box[:, :2]], axis=1))
        tracks.keep(tracks.misses <= p["max_age"])
        return out

    def _previous_observations(self) -> np.ndarray:
        """Per track, the observation delta_t frames back, or the nearest after it, or else the latest (the
        reference's k_previous_obs); NO_BOX for a track never observed."""
        k, tracks = self.params["delta_t"], self.tracks
        within = tracks.recent_age >= (tracks.age[:, None] - k)
        slot = np.where(within.any(axis=1), within.argmax(axis=1), k - 1)
        out = tracks.recent[np.arange(len(slot)), slot]
        out[tracks.recent_age[:, -1] == NONE] = NO_BOX
        return out

    def _observe(self, t: np.ndarray, boxes: np.ndarray, previous: np.ndarray) -> None:
        """Tracks t matched to boxes (x1, y1, x2, y2, confidence): direction, observation history and counts as the
        reference's KalmanBoxTracker.update, the filter re-updated along the gap first where it was frozen."""
        if not len(t):
            return
        tracks = self.tracks
        had = tracks.last[t].sum(axis=1) >= 0  # the reference's test for "observed before" (a box's sum, as it is)
        tracks.velocity[t[had]] = unit_direction(previous[had], boxes[had])
        tracks.last[t] = boxes
        tracks.recent_age[t] = np.concatenate([tracks.recent_age[t, 1:], tracks.age[t, None]], axis=1)
        tracks.recent[t] = np.concatenate([tracks.recent[t, 1:], boxes[:, None]], axis=1)
        z = corners_to_z(boxes[:, :4])
        rewind = ~tracks.observed[t] & tracks.frozen[t]
        virtual = self._reupdate(t[rewind], z[rewind]) if rewind.any() else None
        tracks.last_z[t] = z
        if virtual is not None:
            tracks.last_z[t[rewind]] = virtual
        tracks.observed[t], tracks.frozen[t] = True, False
        tracks.matched(t)
        tracks.kf.update(t, z)

    def _reupdate(self, t: np.ndarray, z: np.ndarray) -> np.ndarray:
        """ORU: rewind tracks t to their state at the first missed frame and update them with virtual measurements
        on the straight line from the last measurement to z, one per frame of the gap, predicting between (the
        reference's unfreeze). Returns the last virtual measurements."""
        tracks = self.tracks
        gap = tracks.misses[t]
        x1, y1, w1, h1 = z_to_xywh(tracks.last_z[t])
        x2, y2, w2, h2 = z_to_xywh(z)
        step = [(b - a) / gap for a, b in ((x1, x2), (y1, y2), (w1, w2), (h1, h2))]
        bank = KalmanBank(tracks.kf.m)
        bank.x, bank.P = tracks.saved_x[t].copy(), tracks.saved_P[t].copy()
        virtual = np.zeros((len(t), 4))
        for i in range(int(gap.max())):
            rows = np.flatnonzero(gap > i)
            x, y, w, h = (a[rows] + (i + 1) * s[rows] for a, s in zip((x1, y1, w1, h1), step))
            virtual[rows] = np.stack([x, y, w * h, w / h], axis=1)
            bank.update(rows, virtual[rows])
            more = gap > i + 1
            x_next, P_next = bank.x @ bank.m.F.T, bank.m.F @ bank.P @ bank.m.F.T + bank.m.Q
            bank.x[more], bank.P[more] = x_next[more], P_next[more]
        tracks.kf.x[t], tracks.kf.P[t] = bank.x, bank.P
        return virtual

    def _miss(self, t: np.ndarray) -> None:
        """Tracks t unmatched: the first miss after a measurement saves the filter's state for a later re-update."""
        tracks = self.tracks
        first = t[tracks.observed[t]]
        tracks.saved_x[first], tracks.saved_P[first] = tracks.kf.x[first], tracks.kf.P[first]
        tracks.frozen[first], tracks.observed[t] = True, False

    def _start(self, boxes: np.ndarray) -> None:
        """Tracks born from detections (x1, y1, x2, y2, confidence): never observed yet, as the reference's."""
        self.tracks.add(len(boxes), corners_to_z(boxes[:, :4]), last=NO_BOX, recent_age=NONE)


def unit_direction(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(dy, dx) from the centres of corner boxes a to those of b, divided by the distance + 1e-6 (the reference's
    speed_direction)."""
    dx = (b[:, 0] + b[:, 2]) / 2.0 - (a[:, 0] + a[:, 2]) / 2.0
    dy = (b[:, 1] + b[:, 3]) / 2.0 - (a[:, 1] + a[:, 3]) / 2.0
    norm = np.sqrt(dy**2 + dx**2) + 1e-6
    return np.stack([dy / norm, dx / norm], axis=1)


def direction_agreement(dets: np.ndarray, previous: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """(tracks, dets): (pi/2 - the angle between each track's velocity and the direction from its previous
    observation to each detection) / pi, in [-1/2, 1/2] (the reference's OCM term before weighting)."""
    dx = (dets[:, 0] + dets[:, 2]) / 2.0 - ((previous[:, 0] + previous[:, 2]) / 2.0)[:, None]
    dy = (dets[:, 1] + dets[:, 3]) / 2.0 - ((previous[:, 1] + previous[:, 3]) / 2.0)[:, None]
    norm = np.sqrt(dx**2 + dy**2) + 1e-6
    cos = np.clip(velocity[:, 1:2] * (dx / norm) + velocity[:, 0:1] * (dy / norm), -1, 1)
    return (np.pi / 2.0 - np.abs(np.arccos(cos))) / np.pi


def corners_to_z(corners: np.ndarray) -> np.ndarray:
    """x1, y1, x2, y2 -> cx, cy, s (area), r = w / (h + 1e-6), as OC-SORT's convert_bbox_to_z."""
    w, h = corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1]
    return np.stack([corners[:, 0] + w / 2.0, corners[:, 1] + h / 2.0, w * h, w / (h + 1e-6)], axis=1)


def z_to_xywh(z: np.ndarray) -> tuple[np.ndarray, ...]:
    """cx, cy, s, r -> (cx, cy, w, h) columns, w = sqrt(s r) and h = sqrt(s / r), as the reference's unfreeze."""
    return z[:, 0], z[:, 1], np.sqrt(z[:, 2] * z[:, 3]), np.sqrt(z[:, 2] / z[:, 3])
