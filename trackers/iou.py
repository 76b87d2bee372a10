"""The IOU tracker (Bochinski, Eiselein, Sikora 2017; "IOU17" in the LMB paper): greedy high-overlap linking."""

from __future__ import annotations

import numpy as np

from .base import Param, Tracker, Tracks, detections
from .parts.assignment import corner_iou, corners


class IouTracker(Tracker):
    """As the reference code (bochinski/iou-tracker, `track_iou`): detections under sigma_l are dropped; each active
    track, in order, takes the remaining detection that overlaps its last box most if that IoU reaches sigma_iou,
    otherwise it ends; unused detections start tracks. A track is kept if it lasted t_min frames and its best score
    reached sigma_h. The method is offline: it reports a kept track in every frame from its first. Online (the env's
    reward and metrics) a track is reported from the frame it meets both conditions; `results()`, which files are
    written from, gives the offline output, numbered in the reference's order. Coordinates stay as given (the
    reference reads them as float32 shifted by one pixel, which its writer shifts back)."""

    name = "iou"
    description = "IOU tracker (Bochinski et al. 2017): greedy IoU linking with sigma_l, sigma_h, sigma_iou, t_min"
    parameters = {
        "sigma_l": Param(0.0, None, "detections below this confidence are dropped", (0.0, 0.9)),
        "sigma_h": Param(0.5, None, "a track is kept only if its best confidence reaches this", (0.1, 0.99)),
        "sigma_iou": Param(0.5, "[0, 1]", "least IoU linking a detection to a track", (0.1, 0.8)),
        "t_min": Param(2, "[1, inf)", "least track length in frames", (1, 10))}

    def reset(self, info=None):
        self.key = np.zeros(0, np.int64)  # active tracks in the reference's order: creation number (the online id)
        self.last, self.max_score, self.length = np.zeros((0, 4)), np.zeros(0), np.zeros(0, np.int64)
        self.next_key = 1
        self.history: list[tuple[np.ndarray, np.ndarray]] = []  # per frame: the active tracks' keys and boxes
        self.finished: list[int] = []  # keys of kept tracks, in the order the reference finishes them

    def _kept(self, rows) -> np.ndarray:
        return (self.max_score[rows] >= self.params["sigma_h"]) & (self.length[rows] >= self.params["t_min"])

    def update(self, obs) -> Tracks:
        p = self.params
        dets = detections(obs)
        dets = dets[dets[:, 4] >= p["sigma_l"]]
        iou = corner_iou(corners(self.last), corners(dets))
        free = np.ones(len(dets), bool)
        match = np.full(len(self.key), -1)
        for r in range(len(self.key)):  # greedy, in track order: each track takes the best detection still free
            if free.any():
                j = int(np.argmax(np.where(free, iou[r], -np.inf)))
                if iou[r, j] >= p["sigma_iou"]:
                    match[r], free[j] = j, False
        ended = np.flatnonzero(match < 0)
        self.finished += self.key[ended[self._kept(ended)]].tolist()
        on = match >= 0
        new = np.flatnonzero(free)
        self.key = np.r_[self.key[on], np.arange(self.next_key, self.next_key + len(new))]
        self.next_key += len(new)
        self.last = np.r_[dets[match[on], :4], dets[new, :4]]
        self.max_score = np.r_[np.maximum(self.max_score[on], dets[match[on], 4]), dets[new, 4]]
        self.length = np.r_[self.length[on] + 1, np.ones(len(new), np.int64)]
        self.history.append((self.key, self.last))
        report = self._kept(slice(None))
        return Tracks.of(self.key[report], self.last[report], self.max_score[report])

    def results(self, online: list[Tracks]) -> list[Tracks]:
        """The published offline output: every frame of each kept track, ids 1, 2, ... in finishing order (tracks
        still active at the end finish last)."""
        finished = self.finished + self.key[self._kept(slice(None))].tolist()
        number = {k: i + 1 for i, k in enumerate(finished)}
        out = []
        for keys, boxes in self.history:
            keep = np.isin(keys, finished)
            out.append(Tracks.of([number[k] for k in keys[keep].tolist()], boxes[keep]))
        return out
