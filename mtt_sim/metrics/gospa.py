"""GOSPA (alpha = 2), the generalised optimal sub-pattern assignment distance between two sets of points or of box
centres, with cut-off c and order p (definition: `mtt_sim.metrics`)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from mtt_sim.boxes import centres
from mtt_sim.metrics.family import Field, LogPass
from mtt_sim.metrics.frame_log import FrameLog


class Gospa(LogPass):
    """GOSPA of each frame's box centres with cut-off `c` and order `p`, its mean over the episode reported."""

    FIELDS = (Field("GOSPA", lower_is_better=True, printed=True),)

    def __init__(self, log: FrameLog, c: float, p: float):
        super().__init__(log)
        self.c, self.p = c, p

    def frame(self, index: int = -1) -> float:
        """GOSPA of one frame of the log (default: the latest)."""
        return gospa_of_points(*self.log.points(index), self.c, self.p)

    def summary(self) -> dict:
        """The mean over frames of each frame's GOSPA."""
        if not len(self.log):
            return {"GOSPA": 0.0}
        return {"GOSPA": float(np.mean([gospa_of_points(a, b, self.c, self.p)
                                        for a, b in zip(*self.log.split_points())]))}


def gospa(a: np.ndarray, b: np.ndarray, c: float, p: float) -> float:
    """GOSPA (alpha = 2) between the centres of two sets of boxes, with cut-off c and order p."""
    return gospa_of_points(centres(a), centres(b), c, p)


def gospa_of_points(a: np.ndarray, b: np.ndarray, c: float, p: float) -> float:
    """GOSPA (alpha = 2) between two point sets (n, 2) and (m, 2), with cut-off c and order p."""
    if not len(a) or not len(b):
        return float((c**p / 2 * (len(a) + len(b))) ** (1 / p))
    dx, dy = a[:, 0, None] - b[None, :, 0], a[:, 1, None] - b[None, :, 1]
    cost = np.minimum(np.sqrt(dx * dx + dy * dy), c) ** p  # assigning at >= c costs what leaving both does
    rows, cols = linear_sum_assignment(cost)
    return float((cost[rows, cols].sum() + c**p / 2 * abs(len(a) - len(b))) ** (1 / p))
