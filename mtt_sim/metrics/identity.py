"""Identity (IDF1, IDP, IDR): the global one-to-one assignment of GT ids to tracker ids, a pass over the nonzero
similarities of every frame laid out flat (definitions: `mtt_sim.metrics`)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from mtt_sim.metrics.family import Field, LogPass
from mtt_sim.metrics.frame_log import FrameLog


class Identity(LogPass):
    """IDF1, IDP, IDR: IDTP is the largest number of frames a one-to-one GT-to-tracker id assignment can match."""

    FIELDS = (Field("IDF1", printed=True), Field("IDP"), Field("IDR"), Field("IDTP", int),
              Field("IDFP", int, lower_is_better=True), Field("IDFN", int, lower_is_better=True))

    def __init__(self, log: FrameLog, threshold: float):
        super().__init__(log)
        self.threshold = threshold

    def summary(self) -> dict:
        flat = self.log.flat()
        hit = flat.sim >= self.threshold
        idtp = 0
        if hit.any():
            gi, ti = _ranks(flat.gt[hit], len(flat.gt_count)), _ranks(flat.trk[hit], len(flat.trk_count))
            potential = np.zeros((gi.max() + 1, ti.max() + 1))
            np.add.at(potential, (gi, ti), 1)
            rows, cols = linear_sum_assignment(potential, maximize=True)
            idtp = int(potential[rows, cols].sum())
        idfn, idfp = flat.num_gt_dets - idtp, flat.num_trk_dets - idtp
        return {"IDF1": idtp / max(1, idtp + 0.5 * idfp + 0.5 * idfn), "IDP": idtp / max(1, idtp + idfp),
                "IDR": idtp / max(1, idtp + idfn), "IDTP": idtp, "IDFP": idfp, "IDFN": idfn}


def _ranks(ids: np.ndarray, size: int) -> np.ndarray:
    """Each id's rank among the distinct ids present (np.unique's inverse, for ids in 0..size-1, without sorting)."""
    present = np.zeros(size, bool)
    present[ids] = True
    return (np.cumsum(present) - 1)[ids]
