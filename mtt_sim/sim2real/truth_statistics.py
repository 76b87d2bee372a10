"""Scene statistics of a ground truth, to hold a scenario against real footage: people per frame, how sharply people
turn, how long they stay."""

from __future__ import annotations

from typing import Sequence

import numpy as np

from mtt_sim.core.frame import Truth

LAG = 5            # frames over which a heading is measured
MIN_MOVE = 0.1     # a heading counts where the feet moved at least this share of the box height over LAG frames


def record(scenario: str, config: dict | None = None, seed: int = 0, steps: int | None = None):
    """One episode without a tracker: each frame's truth and detections (x, y, w, h, confidence)."""
    # imported here: the env module is heavy (the runner imports it too), and only this function needs them
    from mtt_sim.env import TrackingEnv
    from mtt_sim.lab.episode import Episode

    env = TrackingEnv(scenario, config=config, obs_mode="detections")
    truths, detections = [], []
    for frame in Episode(env, seed, steps=steps):
        truths.append(env.truth)
        detections.append(frame.obs["detections"][: int(frame.obs["num_detections"])].astype(float))
    return truths, detections


def tracks(truths: Sequence[Truth]) -> dict[int, np.ndarray]:
    """Per id, rows (frame, feet x, feet y, height) over the frames it is present."""
    out: dict[int, list] = {}
    for k, t in enumerate(truths):
        feet = np.c_[t.boxes[:, 0] + t.boxes[:, 2] / 2, t.boxes[:, 1] + t.boxes[:, 3]]
        for i, (x, y), h in zip(t.ids.tolist(), feet.tolist(), t.boxes[:, 3].tolist()):
            out.setdefault(i, []).append((k, x, y, h))
    return {i: np.array(rows) for i, rows in out.items()}


def heading_changes(truths: Sequence[Truth], lag: int = LAG) -> np.ndarray:
    """Degrees between a person's direction of travel over frames t-lag..t and over t..t+lag, for every t where both
    moves are long enough to have a direction (MIN_MOVE), within stretches of consecutive frames."""
    out = []
    for rows in tracks(truths).values():
        for part in np.split(rows, np.flatnonzero(np.diff(rows[:, 0]) != 1) + 1):
            if len(part) <= 2 * lag:
                continue
            move = part[lag:, 1:3] - part[:-lag, 1:3]
            ok = np.hypot(*move.T) >= MIN_MOVE * part[:-lag, 3]
            angle = np.arctan2(move[:, 1], move[:, 0])
            turn = np.abs((angle[lag:] - angle[:-lag] + np.pi) % (2 * np.pi) - np.pi)
            out.append(np.degrees(turn[ok[lag:] & ok[:-lag]]))
    return np.concatenate(out) if out else np.zeros(0)


def summary(truths: Sequence[Truth]) -> dict:
    """People per frame (mean), 90th percentile of the heading changes, median frames a person stays."""
    turns = heading_changes(truths)
    stays = [len(r) for r in tracks(truths).values()]
    return {"people per frame": float(np.mean([len(t.ids) for t in truths])) if truths else 0.0,
            "heading change p90 (deg)": float(np.percentile(turns, 90)) if len(turns) else float("nan"),
            "median stay (frames)": float(np.median(stays)) if stays else 0.0}
