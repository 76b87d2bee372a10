"""One frame as a source hands it over: the ground truth of everyone in view, the detections, and the truth the
tracks of that frame are scored against. A simulated scene and a recorded sequence both produce these types."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

CLUTTER = -1   # source of a false detection
UNKNOWN = 0    # source of a foreground blob (the image does not say which target made it)


@dataclass(frozen=True)
class Truth:
    """Ground truth of the targets inside the image at one frame (rows aligned)."""

    ids: np.ndarray            # (n,) int64, unique over the episode
    boxes: np.ndarray          # (n, 4) float32, full extent x, y, w, h clipped to the image
    visibility: np.ndarray     # (n,) float32 in [0, 1]: visible pixels / pixels of the unoccluded shape in the image
    visible_boxes: np.ndarray  # (n, 4) float32, extent of the visible pixels (zeros where none)
    depth: np.ndarray          # (n,) float32, larger = nearer the viewer
    labels: np.ndarray         # (n,) int, the value of this target in the label map
    pieces: np.ndarray         # (p, 5) float32: row index into these arrays, x, y, w, h of each visible piece
                               # of a target whose visible region falls apart (all pieces of such a target)

    def __len__(self) -> int:
        return len(self.ids)


@dataclass(frozen=True)
class Detections:
    """One frame's detections: rows x, y, w, h, confidence, and the target id behind each (for tests and overlays)."""

    rows: np.ndarray     # (n, 5) float32
    sources: np.ndarray  # (n,) int64: target id, CLUTTER or UNKNOWN


class ScoredTruth(NamedTuple):
    """What one frame's tracks are scored against (`Source.scored_truth`)."""

    ids: np.ndarray                  # (m,) ids of the scored targets
    boxes: np.ndarray                # (m, 4) their boxes x, y, w, h
    scored_tracks: np.ndarray | slice  # which of the tracks are scored: an index into their rows (a mask or a slice)
    in_view: tuple[np.ndarray, np.ndarray, np.ndarray] | None  # everyone in view (ids, boxes, visibility) for the
                                                               # occlusion windows, which need the hidden too; or None
