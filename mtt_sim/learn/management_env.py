"""TrackManagementEnv: track management as a Gymnasium decision process over the tracking env.

Each frame a base tracker's association (`base="sort"`, or `"bytetrack"`) proposes candidate tracks
(`trackers.parts.management.Candidates`); the agent decides for each candidate whether to report it this frame and whether
to keep it alive. The reward is the tracking env's reward for the reported tracks, unchanged (by default TP - FP - IDSW: the return over the ground-truth count is MOTA).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from mtt_sim.env import TrackingEnv
from mtt_sim.trackers.base import detections
from mtt_sim.trackers.parts.management import BASES, FEATURES, Candidates

DECISION_COLOURS = {"report": (40, 200, 40), "keep": (230, 200, 40), "drop": (220, 50, 50)}


class TrackManagementEnv(gym.Env):
    """**Observation** ``Dict(features=Box(float32, (max_candidates, F)), mask=MultiBinary(max_candidates))``: one row
    of `trackers.parts.management.FEATURES` per candidate track (F of them), zero rows after the candidates, whose rows
    the mask marks. **Action** ``MultiBinary(2 * max_candidates)``: per row, report it this frame, keep it alive, as
    the flattened ``(max_candidates, 2)`` array (flat for learners such as Stable-Baselines3; that 2-D array is taken
    too). Rows past the mask are ignored. **Reward** the tracking env's reward for the reported tracks. Takes anything
    `TrackingEnv` takes (a scenario key or file, a sequence folder, a twin through `config` or `sensor`), in
    detections-only mode; `render()` draws each candidate's decision on the frame."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}

    def __init__(self, scenario: Any = "mot17_like", config: Mapping | None = None, render_mode: str | None = None,
                 max_candidates: int = 64, base: str = "sort", iou_threshold: float = 0.3, **env_kwargs):
        if base not in BASES:
            raise ValueError(f"base={base!r}: allowed: {', '.join(map(repr, BASES))} (the tracker whose association "
                             "proposes candidates)")
        if not isinstance(max_candidates, int) or not 1 <= max_candidates <= 4096:
            raise ValueError(f"max_candidates={max_candidates!r}: allowed: an integer from 1 to 4096")
        self.tracking = TrackingEnv(scenario, config=config, render_mode=render_mode,
                                    obs_mode="frame+detections" if render_mode else "detections", **env_kwargs)
        self.render_mode, self.max_candidates, self.iou_threshold, self.base = (render_mode, max_candidates,
                                                                                iou_threshold, base)
        self.observation_space = spaces.Dict({
            "features": spaces.Box(-1.0, 1.0, (max_candidates, len(FEATURES)), np.float32),
            "mask": spaces.MultiBinary(max_candidates)})
        self.action_space = spaces.MultiBinary(2 * max_candidates)
        self.candidates: Candidates | None = None

    def reset(self, *, seed: int | None = None, options: Mapping | None = None):
        super().reset(seed=seed)
        obs, info = self.tracking.reset(seed=seed, options=options)
        self.candidates = Candidates(tuple(info["image_size"]), self.iou_threshold, self.max_candidates, self.base)
        return self._observe(obs), info

    def _observe(self, obs: Mapping) -> dict[str, np.ndarray]:
        features = self.candidates.propose(detections(obs))
        out = {"features": np.zeros(self.observation_space["features"].shape, np.float32),
               "mask": np.zeros(self.max_candidates, np.int8)}
        out["features"][: len(features)] = features
        out["mask"][: len(features)] = 1
        return out

    def step(self, action):
        if self.candidates is None:
            raise RuntimeError("step() needs reset() first")
        action = np.asarray(action)
        if action.shape not in (self.action_space.shape, (self.max_candidates, 2)):
            raise ValueError(f"action shape {action.shape}: expected {self.action_space.shape} or "
                             f"{(self.max_candidates, 2)} (report, keep for each of max_candidates rows)")
        action = action.reshape(self.max_candidates, 2)
        if not np.isin(action, (0, 1)).all():
            raise ValueError("action: expected 0 or 1 in every entry (report, keep)")
        n = len(self.candidates)
        report, keep = action[:n, 0].astype(bool), action[:n, 1].astype(bool)
        drawings = [{"kind": "box", "box": box, "color": DECISION_COLOURS["report" if r else "keep" if k else "drop"]}
                    for box, r, k in zip(self.candidates.boxes(), report, keep)] if self.render_mode else []
        ids, boxes = self.candidates.decide(report, keep)
        self.tracking.remember_tracks(ids, boxes, drawings, "decisions: green report, yellow keep, red drop")
        obs, reward, terminated, truncated, info = self.tracking.step({"ids": ids, "boxes": boxes})
        return self._observe(obs), reward, terminated, truncated, info

    def render(self):
        """The tracking env's frame (truth, detections, the reported tracks) with each candidate's box outlined by its
        decision: green reported, yellow kept unreported, red dropped."""
        return self.tracking.render()

    def close(self):
        self.tracking.close()
