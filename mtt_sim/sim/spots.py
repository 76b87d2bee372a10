"""Free spots for the people placed at reset: a grid of square cells, so that a test looks only near the spot."""

from __future__ import annotations

import functools

import numpy as np


class SpotGrid:
    """Placed targets' centres and half-sizes in square cells per layer, so a free-spot test looks only at the
    targets near the spot: the same answer as testing all of them, at a cost that does not grow with their number."""

    def __init__(self, cell: float):
        self.cell = max(float(cell), 1.0)
        self.cells: dict[tuple, list] = {}
        self.largest: dict[int, float] = {}  # the largest half-size placed on each layer

    def add(self, layer: int, centre: np.ndarray, half: float):
        cx, cy = (int(v // self.cell) for v in centre)
        self.cells.setdefault((layer, cx, cy), []).append((centre[0], centre[1], half))
        self.largest[layer] = max(self.largest.get(layer, 0.0), half)

    def is_free(self, layer: int, p: np.ndarray, radius: float) -> bool:
        """Whether a footprint of `radius` at p keeps clear of every target on `layer` (centre distance above the sum
        of the two half-sizes). Cells are visited nearest first and the test stops at the first overlap."""
        rings = int((radius + self.largest.get(layer, 0.0)) // self.cell) + 1  # cells that can hold a touching target
        cx, cy = int(p[0] // self.cell), int(p[1] // self.cell)
        for dx, dy in nearest_first(rings):
            placed = self.cells.get((layer, cx + dx, cy + dy))
            if placed:
                rows = np.array(placed)
                if not (np.hypot(*(rows[:, :2] - p).T) > radius + rows[:, 2]).all():
                    return False
        return True


@functools.cache
def nearest_first(rings: int) -> list[tuple[int, int]]:
    """Cell offsets within `rings` of the centre cell, nearest first."""
    offsets = [(dx, dy) for dx in range(-rings, rings + 1) for dy in range(-rings, rings + 1)]
    return sorted(offsets, key=lambda d: abs(d[0]) + abs(d[1]))
