"""ByteTrack (Zhang et al. 2022): associate every detection box, low-confidence ones in a second round."""

from __future__ import annotations

import numpy as np

from .assignment import assign, iou_matrix
from .base import Param, Tracker, Tracks, detections, register
from .kalman import KalmanBank, box_model, boxes_to_z, stop_shrinking_to_nothing, z_to_boxes
from .trackbook import CONFIRMED, LOST, TENTATIVE, TrackBook


@register
class ByteTrack(Tracker):
    """Detections split at track_thresh into high and low (down to low_thresh). First, confirmed and lost tracks
    are matched to high detections (IoU distance <= match_thresh); second, the still-unmatched confirmed tracks
    are matched to low detections (<= second_match_thresh), which recovers occluded, low-scored targets instead
    of discarding them; unmatched confirmed tracks become lost and are kept for track_buffer frames. Tentative
    tracks (born last frame) take the remaining high detections (<= unconfirmed_match_thresh) or die; high
    detections left start tentative tracks if their score reaches new_track_thresh. Reported: confirmed
    tracks matched this frame. Plain IoU distances and SORT's Kalman box model stand in for the paper's
    score-fused IoU and (x, y, aspect, h) filter."""

    name = "bytetrack"
    description = "ByteTrack (Zhang et al. 2022): two-stage association with high- and low-confidence detections"
    parameters = {"track_thresh": Param(0.5), "low_thresh": Param(0.1), "new_track_thresh": Param(0.6),
                  "match_thresh": Param(0.8, "[0, 1]"), "second_match_thresh": Param(0.5, "[0, 1]"),
                  "unconfirmed_match_thresh": Param(0.7, "[0, 1]"), "track_buffer": Param(30, "[0, inf)")}

    def reset(self, info=None):
        self.book = TrackBook(KalmanBank(box_model()))
        self.frame = 0

    def _match(self, rows: np.ndarray, dets: np.ndarray, free: np.ndarray, max_distance: float) -> np.ndarray:
        """Match tracks `rows` to the free detections; update the matched ones; return the matched rows."""
        cols = np.flatnonzero(free)
        matches, _, _ = assign(1 - iou_matrix(z_to_boxes(self.book.kf.x[rows]), dets[cols, :4]), max_distance)
        r, c = rows[matches[:, 0]], cols[matches[:, 1]]
        self.book.hit(r, dets[c, :4], dets[c, 4], boxes_to_z(dets[c, :4]))
        free[c] = False
        return r

    def update(self, obs) -> Tracks:
        p, book = self.params, self.book
        dets = detections(obs)
        self.frame += 1
        high = dets[dets[:, 4] >= p["track_thresh"]]
        low = dets[(dets[:, 4] >= p["low_thresh"]) & (dets[:, 4] < p["track_thresh"])]
        stop_shrinking_to_nothing(book.kf)
        book.predict()
        free_high, free_low = np.ones(len(high), bool), np.ones(len(low), bool)
        pool = np.flatnonzero(book.state != TENTATIVE)
        first = self._match(pool, high, free_high, p["match_thresh"])
        book.state[first] = CONFIRMED
        tracked = np.setdiff1d(pool[book.state[pool] == CONFIRMED], first)
        second = self._match(tracked, low, free_low, p["second_match_thresh"])
        book.state[np.setdiff1d(tracked, second)] = LOST
        new = np.flatnonzero(book.state == TENTATIVE)
        confirmed = self._match(new, high, free_high, p["unconfirmed_match_thresh"])
        book.state[confirmed] = CONFIRMED
        dead = ((book.state == TENTATIVE) & (book.misses > 0)) | ((book.state == LOST) & (book.misses > p["track_buffer"]))
        book.keep(~dead)
        born = high[free_high & (high[:, 4] >= p["new_track_thresh"])]
        book.add(born[:, :4], born[:, 4], boxes_to_z(born[:, :4]), state=CONFIRMED if self.frame == 1 else TENTATIVE)
        report = (book.state == CONFIRMED) & (book.misses == 0)
        return Tracks.of(book.ids[report], z_to_boxes(book.kf.x[report]), book.score[report])
