"""The IOU tracker (Bochinski, Eiselein, Sikora 2017; "IOU17" in seed 004): greedy high-overlap linking."""

from __future__ import annotations

import numpy as np

from .assignment import iou_matrix
from .base import Param, Tracker, Tracks, detections, register
from .trackbook import TrackBook


@register
class IouTracker(Tracker):
    """Detections under sigma_l are dropped; each active track, in order, takes the remaining detection that
    overlaps its last box most if that IoU reaches sigma_iou, otherwise it ends; unused detections start tracks.
    The paper keeps a finished track only if it lasted t_min frames and its best score reached sigma_h; online,
    a track is reported from the frame it meets both conditions (the paper, being offline, also reports its
    earlier frames)."""

    name = "iou"
    description = "IOU tracker (Bochinski et al. 2017): greedy IoU linking with sigma_l, sigma_h, sigma_iou, t_min"
    parameters = {"sigma_l": Param(0.0), "sigma_h": Param(0.5), "sigma_iou": Param(0.5, "[0, 1]"),
                  "t_min": Param(2, "[1, inf)")}

    def reset(self, info=None):
        self.book = TrackBook()

    def update(self, obs) -> Tracks:
        p, book = self.params, self.book
        dets = detections(obs)
        dets = dets[dets[:, 4] >= p["sigma_l"]]
        iou = iou_matrix(book.boxes, dets[:, :4])
        free = np.ones(len(dets), bool)
        match = np.full(len(book), -1)
        for r in range(len(book)):  # greedy, in track order, as the paper's algorithm
            if free.any():
                j = int(np.argmax(np.where(free, iou[r], -1.0)))
                if iou[r, j] >= p["sigma_iou"]:
                    match[r], free[j] = j, False
        rows = np.flatnonzero(match >= 0)
        book.predict()
        book.hit(rows, dets[match[rows], :4], np.maximum(book.score[rows], dets[match[rows], 4]))
        book.keep(book.misses == 0)
        book.add(dets[free, :4], dets[free, 4])
        report = (book.hits >= p["t_min"]) & (book.score >= p["sigma_h"])
        return Tracks.of(book.ids[report], book.boxes[report], book.score[report])
