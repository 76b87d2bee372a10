"""GOSPA (alpha = 2), the generalised optimal sub-pattern assignment distance between two sets of points or of box
centres, with cut-off c and order p (definition: `mtt_sim.metrics`)."""

from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from mtt_sim.boxes import centres


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
