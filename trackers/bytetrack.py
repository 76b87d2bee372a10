"""ByteTrack (Zhang et al. 2022): associate every detection box, low-confidence ones in a second round; as the
reference code ifzhang/ByteTrack (yolox/tracker, commit d1bf019) computes it."""

from __future__ import annotations

import numpy as np

from .base import Param, Tracker, Tracks, detections, frame_of
from .parts.assignment import corners, lapjv, plus_one_iou
from .parts.boxes import tlwh_to_xyah, xyah_to_corners, xyah_to_tlwh
from .parts.camera_motion import METHODS, CameraMotion, warp_centres
from .parts.kalman import xyah_initiate, xyah_predict, xyah_update
from .parts.track_table import TrackTable

TRACKED, LOST, REMOVED = 1, 2, 3  # the reference's TrackState (New = 0 is never stored)


class ByteTrack(Tracker):
    """Detections above track_thresh are high, those between 0.1 and track_thresh low. Tracked and lost tracks
    (lost ones with their height velocity zeroed) predict with a Kalman filter on (cx, cy, aspect, height) whose noise
    scales with the height, and take high detections (cost 1 - IoU x score, at most match_thresh); tracked tracks
    left take low detections (1 - IoU, at most 0.5) or become lost; tracks born last frame take the remaining high
    detections (1 - IoU x score, at most 0.7) or are removed; high detections left with a score of track_thresh + 0.1
    start tracks, reported from their second match (from the first frame at once). Lost tracks are removed after
    int(frame_rate / 30 x track_buffer) frames; a tracked and a lost track overlapping by IoU > 0.85 keep the older.
    IoU counts pixels inclusively (+1), as cython_bbox does, and assignments come from `lap` with a cost limit, as in
    the reference; its list order is kept throughout, so ids and boxes agree with its output. mot20=true leaves out
    the score in the costs, as the reference does for MOT20."""

    name = "bytetrack"
    description = "ByteTrack (Zhang et al. 2022): two-stage association with high- and low-confidence detections"
    parameters = {
        "track_thresh": Param(0.5, None, "confidence splitting high from low detections", (0.1, 0.95)),
        "track_buffer": Param(30, "[0, inf)", "frames a lost track is kept (at 30 frames/s)", (1, 120, "log")),
        "match_thresh": Param(0.8, "[0, 1]", "largest cost (1 - IoU x score) of a first-round match", (0.5, 0.99)),
        "mot20": Param(False, None, "the reference's MOT20 switch: no score fusion in the first round"),
        "frame_rate": Param(30.0, "(0, inf)", "the video's frames per second (scales track_buffer)"),
        "cmc": Param("none", METHODS, "camera-motion compensation from the frame (beyond the paper, as BoT-SORT; see "
                                      "parts/camera_motion.py): tracked, lost and new tracks moved with the image")}

    @property
    def needs_frame(self) -> bool:
        return self.params["cmc"] != "none"

    def reset(self, info=None):
        self.camera = CameraMotion(self.params["cmc"])
        self.tracks = TrackTable(mean=(np.float64, (8,)), cov=(np.float64, (8, 8)), state=np.int8, activated=bool,
                                 score=np.float64)
        self.tracked: list[int] = []  # rows of the table, in the reference's list order
        self.lost: list[int] = []
        self.removed_ids: set[int] = set()

    def update(self, obs) -> Tracks:
        p = self.params
        dets = detections(obs)
        self.tracks.tick()
        xyxy = corners(dets)  # the reference is given x1, y1, x2, y2
        tlwh = np.concatenate([xyxy[:, :2], xyxy[:, 2:] - xyxy[:, :2]], axis=1)
        score = dets[:, 4]
        high = np.flatnonzero(score > p["track_thresh"])
        low = np.flatnonzero((score > 0.1) & (score < p["track_thresh"]))
        unconfirmed = [r for r in self.tracked if not self.tracks.activated[r]]
        pool = _joint([r for r in self.tracked if self.tracks.activated[r]], self.lost)
        self._predict(pool)
        if self.needs_frame:
            moved = pool + unconfirmed
            warp = self.camera.estimate(frame_of(obs), tlwh)
            tracks = self.tracks
            tracks.mean[moved], tracks.cov[moved] = warp_centres(tracks.mean[moved], tracks.cov[moved], warp,
                                                                 "centre_aspect_height")
        activated, refound, lost_now, removed_now = [], [], [], []
        # every IoU the three rounds read: a round's tracks are not corrected before it (unconfirmed ones never move)
        iou = plus_one_iou(xyah_to_corners(self.tracks.mean[pool + unconfirmed]), corners(tlwh))
        n = len(pool)

        # first association: tracked and lost tracks with the high detections
        matches, left_tracks, left_high = self._associate(iou[:n][:, high], score[high], p["match_thresh"])
        matched = [pool[t] for t in matches[:, 0].tolist()]
        for r in matched:
            (activated if self.tracks.state[r] == TRACKED else refound).append(r)
        corrected, by = [matched], [high[matches[:, 1]]]  # corrected together at the end: no round reads another's
        # second association: tracked tracks left with the low detections
        rest_at = [t for t in left_tracks.tolist() if self.tracks.state[pool[t]] == TRACKED]
        rest = [pool[t] for t in rest_at]
        matches, still, _ = self._associate(iou[rest_at][:, low], None, 0.5)
        matched = [rest[t] for t in matches[:, 0].tolist()]
        activated += matched
        corrected.append(matched)
        by.append(low[matches[:, 1]])
        for t in still.tolist():
            if self.tracks.state[rest[t]] != LOST:
                self.tracks.state[rest[t]] = LOST
                lost_now.append(rest[t])
        # tracks born last frame with the high detections left
        high = high[left_high]
        matches, left_new, left_high = self._associate(iou[n:][:, high], score[high], 0.7)
        matched = [unconfirmed[t] for t in matches[:, 0].tolist()]
        activated += matched
        corrected.append(matched)
        by.append(high[matches[:, 1]])
        self._correct(sum(corrected, []), np.concatenate(by), tlwh, score)
        for t in left_new.tolist():
            self.tracks.state[unconfirmed[t]] = REMOVED
            removed_now.append(unconfirmed[t])
        # new tracks
        born = high[left_high]
        born = born[score[born] >= p["track_thresh"] + 0.1]
        activated += self._start(tlwh[born], score[born])
        # lost too long
        patience = int(p["frame_rate"] / 30.0 * p["track_buffer"])
        for r in self.lost:
            if self.tracks.misses[r] > patience:
                self.tracks.state[r] = REMOVED
                removed_now.append(r)
        self._rearrange(activated, refound, lost_now, removed_now)
        out = [r for r in self.tracked if self.tracks.activated[r]]
        return Tracks.of(self.tracks.ids[out], xyah_to_tlwh(self.tracks.mean[out]), self.tracks.score[out])

    def _predict(self, rows: list[int]) -> None:
        if rows:
            mean = self.tracks.mean[rows]
            mean[self.tracks.state[rows] != TRACKED, 7] = 0
            self.tracks.mean[rows], self.tracks.cov[rows] = xyah_predict(mean, self.tracks.cov[rows])

    def _associate(self, iou: np.ndarray, score: np.ndarray | None, limit: float):
        """(matches (track index, detection index), unmatched track indices, unmatched detection indices) of tracks and
        detections by their `iou`: cost 1 - IoU (times the score unless mot20 or `score` is None), capped at `limit`."""
        if not iou.size:
            return np.zeros((0, 2), np.intp), np.arange(iou.shape[0]), np.arange(iou.shape[1])
        cost = 1 - iou
        if score is not None and not self.params["mot20"]:
            cost = 1 - (1 - cost) * score[None, :]
        return lapjv(cost, limit)

    def _correct(self, rows: list[int], dets: np.ndarray, tlwh: np.ndarray, score: np.ndarray) -> None:
        """Matches of track `rows` with detections `dets`: filters corrected, tracks tracked and activated (re-found,
        if they were lost)."""
        if not rows:
            return
        tracks = self.tracks
        tracks.mean[rows], tracks.cov[rows] = xyah_update(tracks.mean[rows], tracks.cov[rows], tlwh_to_xyah(tlwh[dets]))
        tracks.state[rows], tracks.activated[rows], tracks.score[rows] = TRACKED, True, score[dets]
        tracks.matched(rows)

    def _start(self, tlwh: np.ndarray, score: np.ndarray) -> list[int]:
        """New tracks (rows appended), activated at once only in the first frame."""
        n = len(tlwh)
        if not n:
            return []
        mean, cov = xyah_initiate(tlwh_to_xyah(tlwh))
        first = len(self.tracks.ids)
        self.tracks.add(n, mean=mean, cov=cov, state=TRACKED, activated=self.tracks.frame == 1, score=score)
        return list(range(first, first + n))

    def _rearrange(self, activated, refound, lost_now, removed_now) -> None:
        """The reference's list bookkeeping at the end of a frame, in its order (ids and duplicates depend on it)."""
        tracked = _joint(_joint([r for r in self.tracked if self.tracks.state[r] == TRACKED], activated), refound)
        in_tracked = set(tracked)
        lost = [r for r in self.lost if r not in in_tracked] + lost_now
        lost = [r for r in lost if int(self.tracks.ids[r]) not in self.removed_ids]
        self.removed_ids.update(int(self.tracks.ids[r]) for r in removed_now)
        self.tracked, self.lost = self._without_duplicates(tracked, lost)
        self._compact()

    def _without_duplicates(self, tracked: list[int], lost: list[int]) -> tuple[list[int], list[int]]:
        """A tracked and a lost track with 1 - IoU < 0.15: the one that has been tracked for fewer frames goes."""
        if not tracked or not lost:
            return tracked, lost
        boxes = xyah_to_corners(self.tracks.mean[tracked + lost])
        close = np.argwhere(1 - plus_one_iou(boxes[:len(tracked)], boxes[len(tracked):]) < 0.15)
        age = self.tracks.age - self.tracks.misses  # frames from a track's birth to its last match
        drop_a = {p for p, q in close if not age[tracked[p]] > age[lost[q]]}
        drop_b = {q for p, q in close if age[tracked[p]] > age[lost[q]]}
        return ([r for i, r in enumerate(tracked) if i not in drop_a], [r for i, r in enumerate(lost) if i not in drop_b])

    def _compact(self) -> None:
        """Drop the rows of tracks in neither list (their ids stay in removed_ids), keeping the lists' order."""
        alive = self.tracked + self.lost
        if len(self.tracks.ids) < 2 * len(alive) + 64:
            return
        keep = np.zeros(len(self.tracks.ids), bool)
        keep[alive] = True
        new_row = np.cumsum(keep) - 1
        self.tracks.keep(keep)
        self.tracked, self.lost = [int(new_row[r]) for r in self.tracked], [int(new_row[r]) for r in self.lost]


def _joint(a: list[int], b: list[int]) -> list[int]:
    """The reference's joint_stracks: the rows of `a`, then those of `b` not in `a`."""
    seen = set(a)
    return a + [r for r in dict.fromkeys(b) if r not in seen]
