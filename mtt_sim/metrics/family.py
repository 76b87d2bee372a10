"""What a metric family is: a class that updates on each frame and declares the fields it reports.

`EpisodeMetrics` holds one of each family (CLEAR, identity, HOTA, GOSPA, the occlusion windows, the episode's counts)
and builds everything else from their declarations: the summary's keys and types, the per-target tables, the keys
the command line prints and which way each metric is better. TrackEval's metric classes declare their fields the
same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, NamedTuple, Protocol

import numpy as np

if TYPE_CHECKING:
    from mtt_sim.metrics.frame_log import FrameLog


@dataclass(frozen=True)
class Field:
    """One number a family reports: its name, its type (a float may be None where nothing was counted), whether a
    lower value is better (counts of errors, distances) and whether the command line prints it."""

    name: str
    kind: type = float
    lower_is_better: bool = False
    printed: bool = False

    def value(self, v):
        """`v` as this field's type, None kept."""
        return None if v is None else self.kind(v)


class Frame(NamedTuple):
    """One checked frame, as every family sees it: the ids and boxes of the scored truth and of the tracks, the dense
    indices the episode's log gave their ids, their similarities, and everyone in view (or None)."""

    gt_ids: np.ndarray
    gt_boxes: np.ndarray
    trk_ids: np.ndarray
    trk_boxes: np.ndarray
    g: np.ndarray
    t: np.ndarray
    sim: np.ndarray
    everyone: tuple[np.ndarray, np.ndarray, np.ndarray] | None


class Family(Protocol):
    """A metric family: `FIELDS` its summary gives, in order, and `PER_TARGET` what it gives each ground-truth id."""

    FIELDS: tuple[Field, ...]
    PER_TARGET: tuple[Field, ...]

    def update(self, frame: Frame) -> None:
        """Take one frame (a family that reads the episode's log at the end has nothing to do here)."""

    def summary(self) -> dict:
        """Its fields for the frames so far."""

    def per_target(self) -> dict[int, dict]:
        """Its per-target fields by ground-truth id (the ids it has seen)."""


class LogPass:
    """A family computed at the end of the episode from its log (`FrameLog`), which already holds every frame:
    nothing to do per frame, nothing per target."""

    PER_TARGET: tuple[Field, ...] = ()

    def __init__(self, log: FrameLog):
        self.log = log

    def update(self, frame: Frame) -> None:
        """Nothing: the episode's log holds the frame."""

    def per_target(self) -> dict[int, dict]:
        return {}
