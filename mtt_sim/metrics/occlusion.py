"""The occlusion windows: how a tracker holds a target through an occlusion and takes it back after.

Scored where the truth of every target in view, hidden ones too, is passed to `EpisodeMetrics.update` as `everyone`
(None, 0 otherwise). A target is *hidden* in a frame where its visibility is below HIDDEN (0.05); its *holder* is the
track CLEAR-matched to it in the latest frame it was matched (none before its first match).
HiddenCentreError: the mean distance in pixels between a hidden target's box centre and its holder's reported box
centre, over the hidden frames in which the holder is reported.
An *occlusion* begins at a hidden frame of a target that has a holder and no occlusion under way; it is *revealed* at
the first later frame where the target is at least REVEALED (0.5) visible, and *re-acquired* if its holder at the
beginning is CLEAR-matched to the target in one of the WINDOW (20) frames from that one on. An occlusion is decided
when its window has passed. Reacquired: the share re-acquired among those decided; Occlusions: how many were decided.
One whose window the episode cuts short is not counted, re-acquired or not, so that where an episode ends favours no
tracker. HiddenCentreError and Reacquired are None where nothing was counted.
"""

from __future__ import annotations

import numpy as np

from mtt_sim.boxes import centres, check_frame, rows_of
from mtt_sim.metrics.clear import Clear
from mtt_sim.metrics.family import Field, Frame
from mtt_sim.metrics.frame_log import Grow, IdIndex

HIDDEN, REVEALED, WINDOW = 0.05, 0.5, 20  # the occlusion windows' visibilities and frames (module docstring)
_CLEAR, _HIDDEN, _WINDOW = 0, 1, 2  # a target's occlusion: none under way, hidden and not yet revealed, in its window


class OcclusionWindows:
    """The occlusion-window measures (module docstring), kept per target id in growing arrays; a target's holder is
    the track that `clear` matched to it."""

    FIELDS = (Field("HiddenCentreError", lower_is_better=True, printed=True), Field("Reacquired", printed=True),
              Field("Occlusions", int, printed=True))
    PER_TARGET = (Field("HiddenCentreError", lower_is_better=True), Field("Reacquired"))

    def __init__(self, clear: Clear):
        self.clear = clear
        self.ids = IdIndex()
        self.holder = Grow(-1, np.int64)      # tracker id of the latest match
        self.stage = Grow(_CLEAR, np.int8)    # where each target's occlusion stands
        self.owed = Grow(-1, np.int64)        # the holder an occlusion under way waits for
        self.deadline = Grow(-1, np.int64)    # the last frame of its window
        self.won = Grow(False, bool)          # whether the holder has matched the target in the window so far
        self.error = Grow(0.0, float, 2)      # summed hidden centre error, frames counted
        self.decided = Grow(0, np.int64, 2)   # occlusions re-acquired, occlusions decided
        self.frame = -1

    def update(self, frame: Frame) -> None:
        """One frame with everyone in view (none: nothing to score), after CLEAR matched it."""
        if frame.everyone is not None:
            rows, cols = self.clear.pairs
            self._update(*frame.everyone, frame.trk_ids, frame.trk_boxes, frame.gt_ids[rows], frame.trk_ids[cols])

    def _update(self, ids, boxes, visibility, trk_ids, trk_boxes, matched_gt, matched_trk) -> None:
        """One frame: every target in view (ids, boxes, visibility), the reported tracks, the CLEAR matches. Most
        frames have nobody hidden and no occlusion under way: they only note who holds whom."""
        self.frame += 1
        g = self.ids(ids)
        n = len(self.ids)
        holder, stage = self.holder.ensure(n), self.stage.ensure(n)
        matched_to = np.full(n, -1, np.int64)
        matched_to[self.ids(matched_gt)] = matched_trk
        if (visibility < HIDDEN).any() or stage[:n].any():
            self._windows(g, boxes, visibility, trk_ids, trk_boxes, matched_to)
        now = np.flatnonzero(matched_to >= 0)
        holder[now] = matched_to[now]

    def _windows(self, g, boxes, visibility, trk_ids, trk_boxes, matched_to) -> None:
        """Open, reveal and decide occlusions, and add the hidden frames' centre errors."""
        n = len(self.ids)
        holder, stage, owed, deadline, won = (a.ensure(n) for a in (self.holder, self.stage, self.owed, self.deadline,
                                                                     self.won))
        error, decided = self.error.ensure(n), self.decided.ensure(n)
        revealed = g[(stage[g] == _HIDDEN) & (visibility >= REVEALED)]
        stage[revealed], deadline[revealed] = _WINDOW, self.frame + WINDOW - 1
        waiting = np.flatnonzero(stage[:n] == _WINDOW)
        won[waiting] |= matched_to[waiting] == owed[waiting]
        over = waiting[deadline[waiting] <= self.frame]  # decided when the window has passed, won or not
        decided[over, 0] += won[over]
        decided[over, 1] += 1
        stage[over], won[over] = _CLEAR, False
        at = np.flatnonzero((visibility < HIDDEN) & (holder[g] >= 0))  # rows of the hidden targets with a holder
        held = g[at]
        starting = held[stage[held] == _CLEAR]
        stage[starting], owed[starting] = _HIDDEN, holder[starting]
        row = rows_of(trk_ids, holder[held])  # each holder's row among the reported tracks, -1 if not reported
        seen = row >= 0
        if seen.any():
            d = np.linalg.norm(centres(boxes[at[seen]]) - centres(trk_boxes[row[seen]]), axis=1)
            error[held[seen], 0] += d
            error[held[seen], 1] += 1

    def summary(self) -> dict:
        n = len(self.ids)
        error, decided = self.error.ensure(n)[:n].sum(axis=0), self.decided.ensure(n)[:n].sum(axis=0)
        return {"HiddenCentreError": _ratio(error[0], error[1]), "Reacquired": _ratio(decided[0], decided[1]),
                "Occlusions": int(decided[1])}

    def per_target(self) -> dict[int, dict]:
        n = len(self.ids)
        error, decided = self.error.ensure(n), self.decided.ensure(n)
        return {i: {"HiddenCentreError": _ratio(error[k, 0], error[k, 1]),
                    "Reacquired": _ratio(decided[k, 0], decided[k, 1])} for i, k in self.ids.index.items()}


def _ratio(a: float, b: float) -> float | None:
    """a / b, or None (no value: nothing was counted) when b is 0."""
    return float(a / b) if b else None


def check_everyone(everyone, gt_ids, frame: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Validated (ids, boxes, visibility) of every target in view, or a ValueError naming the problem."""
    try:
        ids, boxes, visibility = everyone
    except (TypeError, ValueError):
        raise ValueError(f"frame {frame}: everyone must be (ids, boxes, visibility) of every target in view") from None
    ids, boxes = check_frame("everyone", ids, boxes, f"frame {frame}")
    visibility = np.asarray(visibility, float)
    if visibility.shape != ids.shape or not np.isfinite(visibility).all():
        raise ValueError(f"frame {frame}: everyone's visibility must be {ids.shape} finite numbers, got shape "
                         f"{visibility.shape}")
    missing = set(np.asarray(gt_ids).tolist()) - set(ids.tolist())
    if missing:
        raise ValueError(f"frame {frame}: everyone must include every scored ground-truth id; missing "
                         f"{sorted(missing)}")
    return ids, boxes, visibility
