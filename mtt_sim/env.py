"""TrackingEnv: the Gymnasium face of the simulator.

Each step the agent answers the current observation (frame and detections) with its tracks;
the environment scores those tracks against the current ground truth, advances the world one
frame, renders it, runs the detector and returns the next observation.
"""

from __future__ import annotations

import os
from collections import deque
from typing import Any, Mapping

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import scenario as scn
from . import viewer
from .metrics import EpisodeMetrics, FrameStats
from .overlay import draw_overlay
from .render import Renderer
from .sensor import Detections, make_sensor
from .truth import Truth, measure
from .world import World

_SPACE_KEYS = ("render.width", "render.height", "sensor.max_detections", "env.max_tracks", "env.obs_mode")
_TRAIL = 12

NO_TRACKS = {"ids": np.zeros(0, np.int64), "boxes": np.zeros((0, 4))}  # the action that reports nothing


class ActionError(ValueError):
    """The agent's action does not describe a valid set of tracks."""


class TrackingEnv(gym.Env):
    """Video multi-target tracking in a simulated scene.

    **Observation** ``Dict(frame=Box(uint8, (H, W, 3)), detections=Box(float32, (max_detections, 5)),
    num_detections=Discrete(max_detections + 1))``: the RGB video frame (absent with
    ``obs_mode="detections"``) and the detector's boxes ``x, y, w, h, confidence`` (top-left and size,
    pixels), padded with zero rows after ``num_detections``.

    **Action** ``Dict(ids=Box(int64, (max_tracks,)), boxes=Box(float32, (max_tracks, 4)),
    num_tracks=Discrete(max_tracks + 1))``: the tracker's tracks for the frame it was shown (the first
    ``num_tracks`` rows count). A dict of unpadded ``ids`` (n,) and ``boxes`` (n, 4) is accepted too.

    **Reward** by ``scoring.reward_mode``, scoring the action against the ground truth of the frame the
    agent was shown: ``"mota"`` (default) TP - FP - IDSW, so the undiscounted return divided by the
    number of ground-truth boxes is MOTA; ``"gospa"`` minus the frame's GOSPA; ``"iou"`` the weighted
    summed similarity of the matches minus weighted FP and FN counts.

    **Episode end** ``terminated`` when no target is alive and none can be born any more;
    ``truncated`` after ``env.max_steps`` steps.

    **Info** at reset: ``init_ids`` and ``init_boxes`` of the targets visible in the first frame, for
    trackers initialised by hand, and ``image_size`` (width, height). Every step: ``info["frame"]``, the frame's counts (tp, fp, fn, idsw,
    num_gt, similarity_sum); on the last step ``info["metrics"]``, the episode's MOTA, IDF1, HOTA, GOSPA
    and the rest (see ``mtt_sim.metrics``). ``env.unwrapped.truth`` is the current ground truth.
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 25}  # an instance lists those that work here

    def __init__(self, scenario: str | os.PathLike | scn.Scenario = "crossing", config: Mapping | None = None,
                 render_mode: str | None = None, obs_mode: str | None = None):
        overrides = scn.expand_dotted(config or {})
        if obs_mode is not None:
            overrides = scn.merge(overrides, {"env": {"obs_mode": obs_mode}})
        self._source = scenario
        self.scenario = scn.load(scenario, overrides)
        self._overrides = overrides
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"render_mode={render_mode!r}: allowed values: None, 'rgb_array', 'human'")
        # "human" needs pygame and a display: where they are missing it is left out of this env's modes (so
        # Gymnasium's check_env checks the modes that work here), and asking for it says how to get it
        self.metadata = {**self.metadata, "render_modes": ["rgb_array"] + (["human"] if viewer.available() else [])}
        if render_mode == "human" and "human" not in self.metadata["render_modes"]:
            raise gym.error.DependencyNotInstalled(viewer.HOW)
        self.render_mode = render_mode
        self._viewer = viewer.Viewer("mtt-sim", self.metadata["render_fps"]) if render_mode == "human" else None
        self.observation_space, self.action_space = self._spaces(self.scenario)
        self.world: World | None = None
        self._done = True

    # ------------------------------------------------------------ spaces

    @staticmethod
    def _spaces(sc: scn.Scenario):
        w, h = sc.render.width, sc.render.height
        nd, nt = sc.sensor.max_detections, sc.env.max_tracks
        det_high = np.tile(np.array([w, h, w, h, 1], np.float32), (nd, 1))
        obs = {"detections": spaces.Box(0.0, det_high, (nd, 5), np.float32), "num_detections": spaces.Discrete(nd + 1)}
        if sc.env.obs_mode == "frame+detections":
            obs = {"frame": spaces.Box(0, 255, (h, w, 3), np.uint8), **obs}
        box_low = np.tile(np.array([-w, -h, 0, 0], np.float32), (nt, 1))  # zero rows pad; used rows need w, h > 0
        box_high = np.tile(np.array([2 * w, 2 * h, 2 * w, 2 * h], np.float32), (nt, 1))
        act = {"ids": spaces.Box(0, 2**31 - 1, (nt,), np.int64), "boxes": spaces.Box(box_low, box_high, (nt, 4), np.float32),
               "num_tracks": spaces.Discrete(nt + 1)}
        return spaces.Dict(obs), spaces.Dict(act)

    # ------------------------------------------------------------ episode

    def reset(self, *, seed: int | None = None, options: Mapping | None = None):
        super().reset(seed=seed)
        options = dict(options or {})
        unknown = set(options) - {"config"}
        if unknown:
            raise ValueError(f"reset options: unknown key(s) {sorted(unknown)}; allowed: 'config'")
        if "config" in options:
            self._reconfigure(options["config"])
        sc = self.scenario
        world_rng, render_rng, sensor_rng = (np.random.default_rng(s) for s in
                                            np.random.SeedSequence(self.np_random.integers(2**63)).spawn(3))
        self.world = World(sc, world_rng)
        self.renderer = Renderer(sc, render_rng)
        if sc.render.camera == "follow":
            self.renderer.camera.follow(self.world)
        empty, _, _ = self.renderer.render(self.world, draw_frame=True, show_targets=False)
        self.sensor = make_sensor(sc, sensor_rng, empty)
        s = sc.scoring
        self.metrics = EpisodeMetrics(s.similarity, s.threshold, s.zero_distance, s.gospa_c, s.gospa_p)
        self.steps = 0
        self._done = False
        self._trails: dict[int, deque] = {}
        self._remembered_at = -1
        self._last_tracks = (np.zeros(0, np.int64), np.zeros((0, 4), np.float32))
        obs = self.observe()
        seen = self.truth.visibility > 0
        info = {"frame_index": 0, "init_ids": self.truth.ids[seen].copy(), "init_boxes": self.truth.boxes[seen].copy(),
                "image_size": (sc.render.width, sc.render.height)}
        if self._viewer:
            self.render()
        return obs, info

    def _reconfigure(self, config: Mapping):
        overrides = scn.merge(self._overrides, scn.expand_dotted(config))
        new = scn.load(self._source, overrides)
        changed = [k for k in _SPACE_KEYS if _get(new, k) != _get(self.scenario, k)]
        if changed:
            raise ValueError(f"reset(options={{'config': ...}}) cannot change {', '.join(changed)}: the observation and "
                             "action spaces are fixed when the env is made; pass them to gym.make(..., config=...) instead")
        self.scenario = new

    def step(self, action):
        if self._done:
            raise RuntimeError("step() called on a finished or unreset episode; call reset() first")
        ids, boxes = self.validate_action(action)
        self.remember_tracks(ids, boxes)
        scored = self.truth.visibility >= self.scenario.scoring.min_visibility
        stats = self.metrics.update(self.truth.ids[scored], self.truth.boxes[scored], ids, boxes)
        reward = self._reward(stats)
        self.world.step()
        self.renderer.camera.advance(self.world)
        self.steps += 1
        obs = self.observe()
        terminated = bool(self.world.finished)
        truncated = bool(self.steps >= self.scenario.env.max_steps and not terminated)
        self._done = terminated or truncated
        info = {"frame_index": self.steps, "frame": dict(vars(stats))}
        if self._done:
            info["metrics"] = self.metrics.summary()
        if self._viewer:
            self.render()
        return obs, float(reward), terminated, truncated, info

    def _reward(self, stats: FrameStats) -> float:
        s = self.scenario.scoring
        if s.reward_mode == "mota":
            return float(stats.tp - stats.fp - stats.idsw)
        if s.reward_mode == "gospa":
            return -self.metrics.frame_gospa()
        return s.iou_weight * stats.similarity_sum - s.fp_weight * stats.fp - s.fn_weight * stats.fn

    def observe(self) -> dict[str, Any]:
        """Render, measure the truth and detect for the world as it is now (after reset/step, or after `world.place`)."""
        sc = self.scenario
        want_frame = sc.env.obs_mode == "frame+detections" or sc.sensor.model == "foreground" or self.render_mode
        frame, labels, boxes = self.renderer.render(self.world, draw_frame=bool(want_frame))
        w = self.world
        self.frame, self.labels = frame, labels
        self.truth: Truth = measure(labels, w.ids, boxes, w.depth(), w.shape_is_rect[w.group],
                                    self.renderer.occluder_image_boxes(), self.renderer.occluder_depth)
        self.detections: Detections = self.sensor.detect(self.truth, labels, frame)
        rows = self.detections.rows
        padded = np.zeros((sc.sensor.max_detections, 5), np.float32)
        padded[: len(rows)] = rows
        obs = {"detections": padded, "num_detections": np.int64(len(rows))}
        if sc.env.obs_mode == "frame+detections":
            obs = {"frame": frame, **obs}
        return obs

    # ------------------------------------------------------------ actions

    def validate_action(self, action) -> tuple[np.ndarray, np.ndarray]:
        """The action's tracks as (ids int64 (n,), boxes float32 (n, 4)), or an ActionError saying what is wrong. Boxes
        are checked as float32, the dtype they are scored and drawn in, against the action space's bounds."""
        nt = self.scenario.env.max_tracks
        if not isinstance(action, Mapping) or not {"ids", "boxes"} <= set(action):
            raise ActionError("action must be a dict with 'ids' and 'boxes' (and 'num_tracks' when padded), "
                              f"got {type(action).__name__}" + (f" with keys {sorted(action)}" if isinstance(action, Mapping) else ""))
        ids, boxes = np.asarray(action["ids"]), np.asarray(action["boxes"])
        if "num_tracks" in action:
            n = action["num_tracks"]
            if not np.issubdtype(np.asarray(n).dtype, np.integer) or np.ndim(n) != 0 or not 0 <= int(n) <= nt:
                raise ActionError(f"action['num_tracks'] = {n!r}: must be an integer in 0..{nt} (env.max_tracks)")
            n = int(n)
            if ids.shape != (nt,) or boxes.shape != (nt, 4):
                raise ActionError(f"padded action: 'ids' must have shape ({nt},) and 'boxes' ({nt}, 4), got "
                                  f"{ids.shape} and {boxes.shape}")
            ids, boxes = ids[:n], boxes[:n]
        elif ids.size == 0 and boxes.size == 0:  # nothing reported, e.g. {"ids": [], "boxes": []}
            ids, boxes = ids.reshape(0), boxes.reshape(0, 4)
        elif ids.ndim != 1 or boxes.shape != (len(ids), 4) or len(ids) > nt:
            raise ActionError(f"unpadded action: 'ids' must have shape (n,) and 'boxes' (n, 4) with n <= {nt}, got "
                              f"{ids.shape} and {boxes.shape}")
        if not ids.size:
            return np.zeros(0, np.int64), np.zeros((0, 4), np.float32)
        if not np.issubdtype(ids.dtype, np.integer):
            raise ActionError(f"action['ids'] must be integers, got dtype {ids.dtype}")
        if not np.issubdtype(boxes.dtype, np.number) or np.iscomplexobj(boxes):
            raise ActionError(f"action['boxes'] must be real numbers, got dtype {boxes.dtype}")
        space = self.action_space["ids"]
        out = (ids < space.low[0]) | (ids > space.high[0])
        if out.any():
            raise ActionError(f"action['ids'] {ids[out][0]} is outside 0..{int(space.high[0])}")
        with np.errstate(over="ignore"):
            boxes = boxes.astype(np.float32)
        bad = ~np.isfinite(boxes).all(axis=1)
        if bad.any():
            raise ActionError(f"action['boxes'] row {int(np.flatnonzero(bad)[0])} is not finite as float32: "
                              f"{np.asarray(action['boxes'])[: len(boxes)][bad][0].tolist()}")
        small = (boxes[:, 2] <= 0) | (boxes[:, 3] <= 0)
        if small.any():
            raise ActionError(f"action['boxes'] row {int(np.flatnonzero(small)[0])} has a non-positive width or height as "
                              f"float32: {boxes[small][0].tolist()} (boxes are x, y, w, h)")
        low, high = self.action_space["boxes"].low[0], self.action_space["boxes"].high[0]
        outside = ((boxes < low) | (boxes > high)).any(axis=1)
        if outside.any():
            (x0, y0, _, _), (x1, y1, w1, h1) = low.tolist(), high.tolist()
            raise ActionError(f"action['boxes'] row {int(np.flatnonzero(outside)[0])} = {boxes[outside][0].tolist()} "
                              f"lies outside the action space: x in [{x0:g}, {x1:g}], y in [{y0:g}, {y1:g}], w in "
                              f"(0, {w1:g}], h in (0, {h1:g}] (at most one image beyond each border)")
        uniq, counts = np.unique(ids, return_counts=True)
        if (counts > 1).any():
            raise ActionError(f"action['ids'] must be unique within a frame; repeated: {uniq[counts > 1].tolist()}")
        return ids.astype(np.int64), boxes

    def remember_tracks(self, ids, boxes):
        """The tracks to draw on the current frame, and their trails (step() records its action's tracks
        itself, unless they were given here first for this frame, e.g. to render before stepping)."""
        if self._remembered_at == self.steps:
            return
        self._remembered_at = self.steps
        ids, boxes = np.asarray(ids, np.int64), np.asarray(boxes, np.float32).reshape(-1, 4)
        self._last_tracks = (ids, boxes)
        centres = boxes[:, :2] + boxes[:, 2:] / 2
        for i, c in zip(ids.tolist(), centres):
            self._trails.setdefault(i, deque(maxlen=_TRAIL)).append(c)
        alive = set(ids.tolist())
        for i in [k for k in self._trails if k not in alive]:
            del self._trails[i]

    # ------------------------------------------------------------ rendering

    def render(self):
        """rgb_array: the frame with ground truth, detections and the last tracks drawn on; human: show it in a window
        (which reset and step also do)."""
        if self.world is None:
            raise RuntimeError("render() needs reset() first")
        if self.render_mode is None:
            gym.logger.warn("render() called with render_mode=None; make the env with render_mode='rgb_array'")
            return None
        img = draw_overlay(self.frame, self.truth, self.detections.rows, *self._last_tracks, self._trails)
        if self._viewer:
            self._viewer.show(img)
            return None
        return img

    def close(self):
        if self._viewer:
            self._viewer.close()


def _get(sc: scn.Scenario, dotted: str):
    obj = sc
    for part in dotted.split("."):
        obj = getattr(obj, part)
    return obj
