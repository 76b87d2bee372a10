"""`EpisodeMetrics`: every metric family of an episode, fed frame by frame, and what their declarations give: the
summary's fields (`METRICS`), the per-target fields (`PER_TARGET`) and the fields the command line prints
(`PRINTED`); `evaluate` on a whole sequence (definitions: `mtt_sim.metrics`)."""

from __future__ import annotations

import warnings
from typing import Sequence

import numpy as np

from mtt_sim.boxes import box_iou, centre_distance, check_frame
from mtt_sim.metrics.clear import Clear, FrameStats
from mtt_sim.metrics.family import Family, Field, Frame, LogPass
from mtt_sim.metrics.frame_log import FrameLog
from mtt_sim.metrics.gospa import Gospa
from mtt_sim.metrics.hota import Hota
from mtt_sim.metrics.identity import Identity
from mtt_sim.metrics.occlusion import OcclusionWindows, check_everyone

SIMILARITIES = ("iou", "centroid")


class Counts(LogPass):
    """The episode's size: frames, ground-truth and tracker rows and ids."""

    FIELDS = (Field("num_frames", int, printed=True), Field("num_gt_dets", int, printed=True),
              Field("num_gt_ids", int, printed=True), Field("num_tracker_dets", int), Field("num_tracker_ids", int))

    def summary(self) -> dict:
        log, flat = self.log, self.log.flat()
        return {"num_frames": len(log), "num_gt_dets": flat.num_gt_dets, "num_gt_ids": len(log.gt_index),
                "num_tracker_dets": flat.num_trk_dets, "num_tracker_ids": len(log.trk_index)}


FAMILIES = (Clear, Identity, Hota, Gospa, OcclusionWindows, Counts)  # in the summary's order


class EpisodeMetrics:
    """Incremental MOT metrics for one sequence: `update` every frame, `summary` at the end."""

    def __init__(self, similarity: str = "iou", threshold: float = 0.5, zero_distance: float = 2.0,
                 gospa_c: float = 50.0, gospa_p: float = 1.0):
        if similarity not in SIMILARITIES:
            raise ValueError(f"similarity={similarity!r}: allowed values: {', '.join(map(repr, SIMILARITIES))}")
        if not 0 < threshold <= 1:
            raise ValueError(f"threshold={threshold!r}: must be in (0, 1]")
        if zero_distance <= 0 or gospa_c <= 0 or gospa_p < 1:
            raise ValueError("zero_distance and gospa_c must be positive and gospa_p >= 1")
        self.similarity, self.threshold, self.zero_distance = similarity, threshold, zero_distance
        self.gospa_c, self.gospa_p = gospa_c, gospa_p
        self._log = FrameLog()  # what the global passes need of every frame
        self.clear = Clear(self._log, threshold)
        self.gospa = Gospa(self._log, gospa_c, gospa_p)
        self.families: tuple[Family, ...] = (self.clear, Identity(self._log, threshold), Hota(self._log), self.gospa,
                                             OcclusionWindows(self.clear), Counts(self._log))

    def _similarity(self, gt_boxes: np.ndarray, trk_boxes: np.ndarray) -> np.ndarray:
        if not len(gt_boxes) or not len(trk_boxes):
            return np.zeros((len(gt_boxes), len(trk_boxes)))
        if self.similarity == "iou":
            return box_iou(gt_boxes, trk_boxes)
        return np.maximum(0.0, 1.0 - centre_distance(gt_boxes, trk_boxes) / self.zero_distance)

    def update(self, gt_ids, gt_boxes, trk_ids, trk_boxes, everyone=None) -> FrameStats:
        """Score one frame: GT ids (n,) and boxes (n, 4), tracker ids (m,) and boxes (m, 4), x, y, w, h. `everyone`:
        (ids, boxes, visibility) of every target in view, hidden ones too, for the occlusion windows. Returns the
        frame's CLEAR counts."""
        log = self._log
        gt_ids, gt_boxes = check_frame("gt", gt_ids, gt_boxes, f"frame {len(log)}")
        trk_ids, trk_boxes = check_frame("tracks", trk_ids, trk_boxes, f"frame {len(log)}")
        if everyone is not None:
            everyone = check_everyone(everyone, gt_ids, len(log))
        g, t = log.gt_index(gt_ids), log.trk_index(trk_ids)
        sim = self._similarity(gt_boxes, trk_boxes)
        log.add_frame(g, t, gt_boxes, trk_boxes, sim)
        frame = Frame(gt_ids, gt_boxes, trk_ids, trk_boxes, g, t, sim, everyone)
        for family in self.families:
            family.update(frame)
        return self.clear.stats

    def __getattr__(self, name: str):
        """Deprecated: the CLEAR counts so far (tp, fp, fn, idsw, similarity_total) are `clear`'s."""
        if name not in ("tp", "fp", "fn", "idsw", "similarity_total"):
            raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
        warnings.warn(f"EpisodeMetrics.{name} moved to EpisodeMetrics.clear.{name}", DeprecationWarning, stacklevel=2)
        return getattr(self.clear, name)

    def __len__(self) -> int:
        """Frames scored so far."""
        return len(self._log)

    def stored_bytes(self) -> int:
        """Bytes this episode's frames are kept in (for the global passes of `summary`)."""
        return self._log.nbytes()

    def frame_gospa(self, index: int = -1) -> float:
        """GOSPA of one stored frame (default: the latest)."""
        return self.gospa.frame(index)

    def summary(self) -> dict:
        """Every family's fields for the frames so far, as a plain dict (definitions: `mtt_sim.metrics`)."""
        out = {}
        for family in self.families:
            values = family.summary()
            out.update((f.name, f.value(values[f.name])) for f in family.FIELDS)
        return out

    def per_target(self) -> dict[int, dict]:
        """Per GT id, each family's per-target fields (None where a family has not seen the id): Coverage and
        CentreError (CLEAR), HiddenCentreError and Reacquired (`mtt_sim.metrics.occlusion`)."""
        out = {int(i): {} for i in self._log.gt_index.index}
        for family in self.families:
            if family.PER_TARGET:
                rows, nothing = family.per_target(), {f.name: None for f in family.PER_TARGET}
                for i, row in out.items():
                    row.update(rows.get(i, nothing))
        return out


def evaluate(gt: Sequence[tuple], tracks: Sequence[tuple], similarity: str = "iou", threshold: float = 0.5,
             zero_distance: float = 2.0, gospa_c: float = 50.0, gospa_p: float = 1.0) -> dict:
    """Metrics of a whole sequence: `gt` and `tracks` are per-frame (ids, boxes) pairs of the same length."""
    gt, tracks = list(gt), list(tracks)
    if len(gt) != len(tracks):
        raise ValueError(f"gt has {len(gt)} frames but tracks has {len(tracks)}; they must be the same length")
    metrics = EpisodeMetrics(similarity, threshold, zero_distance, gospa_c, gospa_p)
    for (gi, gb), (ti, tb) in zip(gt, tracks):
        metrics.update(gi, gb, ti, tb)
    return metrics.summary()


SUMMARY_FIELDS = tuple(f for family in FAMILIES for f in family.FIELDS)  # an episode summary's, in its order
METRICS = tuple(f.name for f in SUMMARY_FIELDS)
PRINTED = tuple(f.name for f in SUMMARY_FIELDS if f.printed)  # what the command line prints of a summary
PER_TARGET = tuple(sorted({f.name for family in FAMILIES for f in family.PER_TARGET}))  # per_target()'s, by name
