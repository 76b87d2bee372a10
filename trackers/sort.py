"""SORT (Bewley, Ge, Ott, Ramos, Upcroft 2016): Kalman-filtered boxes and Hungarian IoU association."""

from __future__ import annotations

from .assignment import assign, iou_matrix
from .base import Param, Tracker, Tracks, detections, register
from .kalman import KalmanBank, box_model, boxes_to_z, stop_shrinking_to_nothing, z_to_boxes
from .trackbook import TrackBook


@register
class Sort(Tracker):
    """Each track is a constant-velocity Kalman filter on (cx, cy, area, aspect); detections are matched to the
    predicted boxes by the Hungarian algorithm on IoU (pairs under iou_threshold rejected); a track is reported
    once it has min_hits consecutive hits (or during the first min_hits frames) and only in frames where it was
    matched, and is deleted after max_age frames without a match. As published, with the reference code's
    noise values; detections below min_confidence are ignored."""

    name = "sort"
    description = "SORT (Bewley et al. 2016): Kalman boxes + Hungarian IoU matching, min_hits, max_age"
    parameters = {"max_age": Param(1, "[0, inf)"), "min_hits": Param(3, "[0, inf)"), "iou_threshold": Param(0.3, "[0, 1]"),
                  "min_confidence": Param(0.0)}

    def reset(self, info=None):
        self.book = TrackBook(KalmanBank(box_model()))
        self.frame = 0

    def update(self, obs) -> Tracks:
        p, book = self.params, self.book
        dets = detections(obs)
        dets = dets[dets[:, 4] >= p["min_confidence"]]
        self.frame += 1
        stop_shrinking_to_nothing(book.kf)
        book.predict()
        predicted = z_to_boxes(book.kf.x)
        matches, _, new = assign(-iou_matrix(predicted, dets[:, :4]), -p["iou_threshold"])
        book.hit(matches[:, 0], dets[matches[:, 1], :4], dets[matches[:, 1], 4], boxes_to_z(dets[matches[:, 1], :4]))
        book.add(dets[new, :4], dets[new, 4], boxes_to_z(dets[new, :4]))
        report = (book.misses == 0) & ((book.streak >= p["min_hits"]) | (self.frame <= p["min_hits"]))
        out = Tracks.of(book.ids[report], z_to_boxes(book.kf.x[report]), book.score[report])
        book.keep(book.misses <= p["max_age"])
        return out
