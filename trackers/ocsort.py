"""OC-SORT (Cao, Pang, Weng, Khirodkar, Kitani, CVPR 2023): SORT made observation-centric, as the official code
noahcao/OC_SORT (trackers/ocsort_tracker, commit bdfbc98) computes it."""

from __future__ import annotations

import numpy as np

from .assignment import corner_iou, lapjv
from .base import Param, Tracker, Tracks, detections, register
from .kalman import KalmanBank, box_model, stop_shrinking_to_nothing
from .sort import associate, state_to_corners, without

NONE = -(2**62)  # the age of an empty slot in a track's recent observations
NO_BOX = np.full(5, -1.0)  # the reference's placeholder for "no observation" (x1, y1, x2, y2, confidence)


@register
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
        self.kf = KalmanBank(box_model())
        self.ids = np.zeros(0, np.int64)
        self.counts = np.zeros((0, 4), np.int64)      # hit streak, hits, age, frames since the last match
        self.last = np.zeros((0, 5))                   # last observation (x1, y1, x2, y2, confidence), or NO_BOX
        self.recent_age = np.zeros((0, k), np.int64)   # ages of the last delta_t observations, oldest first
        self.recent = np.zeros((0, k, 5))              # and those observations
        self.velocity = np.zeros((0, 2))               # unit direction (dy, dx) between observations
        self.observed = np.zeros(0, bool)              # the filter's last update had a measurement
        self.frozen = np.zeros(0, bool)                # a filter state was saved at the first missed frame
        self.saved_x, self.saved_P = np.zeros((0, 7)), np.zeros((0, 7, 7))
        self.last_z = np.zeros((0, 4))                 # the filter's last measurement (cx, cy, s, r), real or virtual
        self.next_id, self.frame = 1, 0

    def _keep(self, mask: np.ndarray) -> None:
        if mask.all():
            return
        self.kf.keep(mask)
        for name in ("ids", "counts", "last", "recent_age", "recent", "velocity", "observed", "frozen", "saved_x",
                     "saved_P", "last_z"):
            setattr(self, name, getattr(self, name)[mask])

    def update(self, obs) -> Tracks:
        p = self.params
        dets = detections(obs)
        dets = np.concatenate([dets[:, :2], dets[:, :2] + dets[:, 2:4], dets[:, 4:]], axis=1)  # given x1, y1, x2, y2
        score = dets[:, 4]
        high = dets[score > p["det_thresh"]]
        low = dets[(score > 0.1) & (score < p["det_thresh"])]
        self.frame += 1
        stop_shrinking_to_nothing(self.kf)
        self.kf.predict()
        self.counts[:, 2] += 1
        self.counts[self.counts[:, 3] > 0, 0] = 0   # a streak ends with a miss
        self.counts[:, 3] += 1
        predicted = state_to_corners(self.kf.x)
        defined = ~np.isnan(predicted).any(axis=1)
        self._keep(defined)
        predicted = predicted[defined]
        previous = self._previous_observations()

        bonus = p["inertia"] * direction_agreement(high, previous, self.velocity).T * high[:, 4:5]
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
            found = rematch(high[left_dets], self.last[left_tracks], p["iou_threshold"])
            if found is not None:
                d, t = found
                pairs.append((high, left_dets[d], left_tracks[t]))
                left_dets = np.sort(left_dets[without(len(left_dets), d)])  # the reference's setdiff1d sorts
                left_tracks = np.sort(left_tracks[without(len(left_tracks), t)])
        t = np.concatenate([t for _, _, t in pairs])
        self._observe(t, np.concatenate([source[d] for source, d, _ in pairs]), previous[t])
        self._miss(left_tracks)
        self._start(high[left_dets])

        streak, misses = self.counts[:, 0], self.counts[:, 3]
        report = (misses < 1) & ((streak >= p["min_hits"]) | (self.frame <= p["min_hits"]))
        box = np.where((self.last.sum(axis=1) < 0)[:, None], state_to_corners(self.kf.x), self.last[:, :4])
        box = box[report]
        out = Tracks.of(self.ids[report], np.concatenate([box[:, :2], box[:, 2:] - box[:, :2]], axis=1))
        self._keep(misses <= p["max_age"])
        return out

    def _previous_observations(self) -> np.ndarray:
        """Per track, the observation delta_t frames back, or the nearest after it, or else the latest (the
        reference's k_previous_obs); NO_BOX for a track never observed."""
        k = self.params["delta_t"]
        within = self.recent_age >= (self.counts[:, 2:3] - k)
        slot = np.where(within.any(axis=1), within.argmax(axis=1), k - 1)
        out = self.recent[np.arange(len(slot)), slot]
        out[self.recent_age[:, -1] == NONE] = NO_BOX
        return out

    def _observe(self, t: np.ndarray, boxes: np.ndarray, previous: np.ndarray) -> None:
        """Tracks t matched to boxes (x1, y1, x2, y2, confidence): direction, observation history and counts as the
        reference's KalmanBoxTracker.update, the filter re-updated along the gap first where it was frozen."""
        if not len(t):
            return
        had = self.last[t].sum(axis=1) >= 0  # the reference's test for "observed before" (a box's sum, as it is)
        self.velocity[t[had]] = unit_direction(previous[had], boxes[had])
        self.last[t] = boxes
        self.recent_age[t] = np.concatenate([self.recent_age[t, 1:], self.counts[t, 2:3]], axis=1)
        self.recent[t] = np.concatenate([self.recent[t, 1:], boxes[:, None]], axis=1)
        z = corners_to_z(boxes[:, :4])
        rewind = ~self.observed[t] & self.frozen[t]
        virtual = self._reupdate(t[rewind], z[rewind]) if rewind.any() else None
        self.last_z[t] = z
        if virtual is not None:
            self.last_z[t[rewind]] = virtual
        self.observed[t], self.frozen[t] = True, False
        self.counts[t, 3] = 0
        self.counts[t, :2] += 1
        self.kf.update(t, z)

    def _reupdate(self, t: np.ndarray, z: np.ndarray) -> np.ndarray:
        """ORU: rewind tracks t to their state at the first missed frame and update them with virtual measurements
        on the straight line from the last measurement to z, one per frame of the gap, predicting between (the
        reference's unfreeze). Returns the last virtual measurements."""
        gap = self.counts[t, 3]
        x1, y1, w1, h1 = z_to_xywh(self.last_z[t])
        x2, y2, w2, h2 = z_to_xywh(z)
        step = [(b - a) / gap for a, b in ((x1, x2), (y1, y2), (w1, w2), (h1, h2))]
        bank = KalmanBank(self.kf.m)
        bank.x, bank.P = self.saved_x[t].copy(), self.saved_P[t].copy()
        virtual = np.zeros((len(t), 4))
        for i in range(int(gap.max())):
            rows = np.flatnonzero(gap > i)
            x, y, w, h = (a[rows] + (i + 1) * s[rows] for a, s in zip((x1, y1, w1, h1), step))
            virtual[rows] = np.stack([x, y, w * h, w / h], axis=1)
            bank.update(rows, virtual[rows])
            more = gap > i + 1
            x_next, P_next = bank.x @ bank.m.F.T, bank.m.F @ bank.P @ bank.m.F.T + bank.m.Q
            bank.x[more], bank.P[more] = x_next[more], P_next[more]
        self.kf.x[t], self.kf.P[t] = bank.x, bank.P
        return virtual

    def _miss(self, t: np.ndarray) -> None:
        """Tracks t unmatched: the first miss after a measurement saves the filter's state for a later re-update."""
        first = t[self.observed[t]]
        self.saved_x[first], self.saved_P[first] = self.kf.x[first], self.kf.P[first]
        self.frozen[first], self.observed[t] = True, False

    def _start(self, boxes: np.ndarray) -> None:
        n, k = len(boxes), self.params["delta_t"]
        self.kf.add(corners_to_z(boxes[:, :4]))
        grow = {"ids": np.arange(self.next_id, self.next_id + n), "counts": np.zeros((n, 4), np.int64),
                "last": np.tile(NO_BOX, (n, 1)), "recent_age": np.full((n, k), NONE),
                "recent": np.zeros((n, k, 5)), "velocity": np.zeros((n, 2)), "observed": np.zeros(n, bool),
                "frozen": np.zeros(n, bool), "saved_x": np.zeros((n, 7)), "saved_P": np.zeros((n, 7, 7)),
                "last_z": np.zeros((n, 4))}
        for name, new in grow.items():
            setattr(self, name, np.concatenate([getattr(self, name), new]))
        self.next_id += n


def rematch(dets: np.ndarray, boxes: np.ndarray, threshold: float) -> tuple[np.ndarray, np.ndarray] | None:
    """A second-round matching by IoU alone (OCR, BYTE): (detection rows, box rows) of the assignment's pairs at or
    over the threshold; None where no IoU exceeds it (the reference then leaves its lists as they are)."""
    iou = corner_iou(dets[:, :4], boxes[:, :4])
    if iou.max() <= threshold:
        return None
    pairs = lapjv(-iou)[0]
    pairs = pairs[iou[pairs[:, 0], pairs[:, 1]] >= threshold]
    return pairs[:, 0], pairs[:, 1]


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
