"""TrackingEnv: the Gymnasium face of a source of frames, a simulated scene or a recorded sequence.

Each step the agent answers the current observation (frame and detections) with its tracks; the environment scores
those tracks against the frame's ground truth, moves its source on one frame and returns the next observation. The
source (`mtt_sim.sources`) makes or reads the truth, detections and frames; the env never asks which kind it holds.
"""

from __future__ import annotations

import os
from collections import deque
from typing import Any, Mapping

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from mtt_sim.metrics import EpisodeMetrics, FrameStats
from mtt_sim.show import viewer
from mtt_sim.show.overlay import draw_banner, draw_debug, draw_legend, draw_overlay, running_metrics
from mtt_sim.sim import scenario as scn
from mtt_sim.sources import Source, open_source

_SPACE_KEYS = ("render.width", "render.height", "sensor.model", "sensor.max_detections", "sensor.conf_offset",
               "sensor.conf_scale", "env.max_tracks", "env.obs_mode")
_TRAIL = 40  # frames of a track's centre drawn behind it: long enough to show where it came from

NO_TRACKS = {"ids": np.zeros(0, np.int64), "boxes": np.zeros((0, 4))}  # the action that reports nothing


class ActionError(ValueError):
    """The agent's action does not describe a valid set of tracks."""


class TrackingEnv(gym.Env):
    """Video multi-target tracking in a simulated scene, or on a recorded sequence.

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

    **Episode end** ``terminated`` when no target is alive and none can be born any more (a recorded
    sequence: after its last frame); ``truncated`` after ``env.max_steps`` steps.

    **Recorded sequences** ``TrackingEnv("path/to/MOT17-02")`` or ``gym.make("mtt_sim/Replay-v0",
    sequence=...)``: detections as written, in float64, bounded by the extremes of the sequence's det.txt
    (raw confidences included); action boxes in float64; ground truth scored as TrackEval scores the
    benchmark (``benchmark=`` overrides the guess from the name and the columns); no gt/: unscored. With
    ``sensor="fitted.toml"`` (a file from ``mtt-sim calibrate``) or ``config={"sensor.model": "synthetic"}`` the
    sequence's ground truth is replayed through the synthetic detector instead (its digital twin), seeded like a
    scenario. ``sensor=`` loads a detector file onto a simulated scenario too.

    **Info** at reset: ``init_ids`` and ``init_boxes`` of the targets visible in the first frame, for
    trackers initialised by hand, ``image_size`` (width, height), ``frame_rate`` and ``length`` (frames;
    None for a scenario, which ends when its world does). Every step: ``info["frame"]``, the frame's counts (tp, fp, fn, idsw,
    num_gt, similarity_sum); a scenario's ``info["camera_warp"]`` (at reset too), the 2x3 float warp that took the
    previous frame's pixel coordinates onto this frame's (BoT-SORT's GMC convention; the identity at reset); on the
    last step ``info["metrics"]``, the episode's MOTA, IDF1, HOTA, GOSPA
    and the rest (see ``mtt_sim.metrics``). ``env.unwrapped.truth`` is the current ground truth.
    """

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 25}  # an instance lists those that work here

    def __init__(self, scenario: str | os.PathLike | scn.Scenario | None = "crossing", config: Mapping | None = None,
                 render_mode: str | None = None, obs_mode: str | None = None, sequence: str | os.PathLike | None = None,
                 benchmark: str | None = None, sensor: str | os.PathLike | None = None, render_scale: int = 1):
        whole = isinstance(render_scale, (int, np.integer)) and not isinstance(render_scale, bool)
        if not whole or not 1 <= render_scale <= 8:
            raise ValueError(f"render_scale={render_scale!r}: allowed: an integer from 1 to 8 (how many times render() "
                             "enlarges the frame)")
        self.render_scale = int(render_scale)
        overrides = scn.expand_dotted(config or {})
        if sensor is not None:  # a fitted detector's file; keys in `config` win
            overrides = scn.merge(scn.read_sensor(sensor), overrides)
        if obs_mode is not None:
            overrides = scn.merge(overrides, {"env": {"obs_mode": obs_mode}})
        what = sequence if sequence is not None else scenario
        if what is None:
            raise ValueError("mtt_sim/Replay-v0 needs sequence='path/to/a/MOTChallenge/sequence/folder'")
        self._what, self._benchmark, self._recorded = what, benchmark, sequence is not None
        self.source: Source = open_source(what, overrides, benchmark, self._recorded)
        if not self.source.scored:
            gym.logger.warn(f"{what}: no gt/gt.txt, so this env runs unscored (reward 0, no info['metrics'])")
        self._overrides = overrides
        if render_mode not in (None, *self.metadata["render_modes"]):
            raise ValueError(f"render_mode={render_mode!r}: allowed values: None, 'rgb_array', 'human'")
        # "human" needs pygame and a display: where they are missing it is left out of this env's modes (so
        # Gymnasium's check_env checks the modes that work here), and asking for it says how to get it
        self.metadata = {**self.metadata, "render_modes": ["rgb_array"] + (["human"] if viewer.available() else []),
                         "render_fps": self.source.frame_rate}  # the source's own clock: videos play at its speed
        if render_mode == "human" and "human" not in self.metadata["render_modes"]:
            raise gym.error.DependencyNotInstalled(viewer.HOW)
        self.render_mode = render_mode
        self._viewer = viewer.Viewer("mtt-sim", self.metadata["render_fps"]) if render_mode == "human" else None
        self.observation_space, self.action_space = self._spaces(self.source)
        self._started = False
        self._done = True

    @property
    def config(self):
        """The configuration this env runs with: the source's env.*, scoring.* and sensor.* tables (a scenario's
        world.*, render.* and groups too)."""
        return self.source.config

    @property
    def scored(self) -> bool:
        """Whether the source has ground truth to score against (a recorded sequence without gt/ has none)."""
        return self.source.scored

    # ------------------------------------------------------------ spaces

    @staticmethod
    def _spaces(source: Source):
        """Detections within the source's bounds, in its dtype (float32 simulated, float64 recorded: as written), the
        rows past num_detections zeros; track boxes in the same dtype, at most one image beyond each border."""
        (w, h), c = source.image_size, source.config
        nd, nt, dtype = c.sensor.max_detections, c.env.max_tracks, source.detection_dtype
        det_low, det_high = source.detection_bounds()
        obs = {"detections": spaces.Box(np.tile(det_low.astype(dtype), (nd, 1)), np.tile(det_high.astype(dtype), (nd, 1)),
                                        (nd, 5), dtype),
               "num_detections": spaces.Discrete(nd + 1)}
        if c.env.obs_mode == "frame+detections":
            obs = {"frame": spaces.Box(0, 255, (h, w, 3), np.uint8), **obs}
        box_low = np.tile(np.array([-w, -h, 0, 0], dtype), (nt, 1))  # zero rows pad; used rows need w, h > 0
        box_high = np.tile(np.array([2 * w, 2 * h, 2 * w, 2 * h], dtype), (nt, 1))
        act = {"ids": spaces.Box(0, 2**31 - 1, (nt,), np.int64), "boxes": spaces.Box(box_low, box_high, (nt, 4), dtype),
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
        rngs = (np.random.default_rng(s) for s in np.random.SeedSequence(self.np_random.integers(2**63)).spawn(3))
        self.source.reset(*rngs)
        self._started = True
        s = self.config.scoring
        self.metrics = EpisodeMetrics(s.similarity, s.threshold, s.zero_distance, s.gospa_c, s.gospa_p)
        self.steps = 0
        self._done = False
        self._trails: dict[int, deque] = {}
        self._remembered_at = -1
        self._last_tracks = (np.zeros(0, np.int64), np.zeros((0, 4)))
        self._answered: tuple | None = None  # what render() draws: the frame the last tracks answer
        self._idf1: tuple[int, float | None] = (0, None)
        obs = self.observe()
        init_ids, init_boxes = self.source.first_targets()
        info = {"frame_index": 0, "init_ids": init_ids, "init_boxes": init_boxes, "image_size": self.source.image_size,
                "frame_rate": self.source.frame_rate, "length": self.source.length}
        if hasattr(self.source, "camera_warp"):
            info["camera_warp"] = self.source.camera_warp
        if self._viewer:
            self.render()
        return obs, info

    def _reconfigure(self, config: Mapping):
        overrides = scn.merge(self._overrides, scn.expand_dotted(config))
        new = open_source(self._what, overrides, self._benchmark, self._recorded)
        changed = [k for k in _SPACE_KEYS if _get(new.config, k) != _get(self.config, k)]
        if changed:
            raise ValueError(f"reset(options={{'config': ...}}) cannot change {', '.join(changed)}: the observation and "
                             "action spaces are fixed when the env is made; pass them to gym.make(..., config=...) instead")
        self.source, self._overrides = new, overrides

    def step(self, action):
        if self._done:
            raise RuntimeError("step() called on a finished or unreset episode; call reset() first")
        ids, boxes = self.validate_action(action)
        self.remember_tracks(ids, boxes)
        truth = self.source.scored_truth(boxes)
        kept = truth.scored_tracks
        stats = self.metrics.update(truth.ids, truth.boxes, ids[kept], boxes[kept], truth.in_view)
        reward = self._reward(stats) if self.scored else 0.0
        self.source.advance()
        self.steps += 1
        obs = self.observe()
        terminated = self.source.finished
        truncated = bool(self.steps >= self.config.env.max_steps and not terminated)
        self._done = terminated or truncated
        info = {"frame_index": self.steps, "frame": dict(vars(stats))}
        if hasattr(self.source, "camera_warp"):
            info["camera_warp"] = self.source.camera_warp
        if self._done and self.scored:
            info["metrics"] = self.metrics.summary()
        if self._viewer:
            self.render()
        return obs, float(reward), terminated, truncated, info

    def _reward(self, stats: FrameStats) -> float:
        s = self.config.scoring
        if s.reward_mode == "mota":
            return float(stats.tp - stats.fp - stats.idsw)
        if s.reward_mode == "gospa":
            return -self.metrics.frame_gospa()
        return s.iou_weight * stats.similarity_sum - s.fp_weight * stats.fp - s.fn_weight * stats.fn

    def observe(self) -> dict[str, Any]:
        """The source's current frame as an observation (after reset/step, or after moving its targets by hand); it
        keeps the frame's truth, detections and image for scoring and render()."""
        c = self.config
        want_frame = c.env.obs_mode == "frame+detections" or c.sensor.model == "foreground" or self.render_mode
        self.truth, self.detections, self.frame = self.source.observe(bool(want_frame))
        rows = self.detections.rows
        padded = np.zeros((c.sensor.max_detections, 5), self.observation_space["detections"].dtype)
        padded[: len(rows)] = rows
        obs = {"detections": padded, "num_detections": np.int64(len(rows))}
        if c.env.obs_mode == "frame+detections":
            obs = {"frame": self.frame, **obs}
        return obs

    # ------------------------------------------------------------ actions

    def validate_action(self, action) -> tuple[np.ndarray, np.ndarray]:
        """The action's tracks as (ids int64 (n,), boxes float32 (n, 4)), or an ActionError saying what is wrong. Boxes
        are checked as float32, the dtype they are scored and drawn in, against the action space's bounds."""
        nt = self.config.env.max_tracks
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
            return np.zeros(0, np.int64), np.zeros((0, 4), self.action_space["boxes"].dtype)
        if not np.issubdtype(ids.dtype, np.integer):
            raise ActionError(f"action['ids'] must be integers, got dtype {ids.dtype}")
        if not np.issubdtype(boxes.dtype, np.number) or np.iscomplexobj(boxes):
            raise ActionError(f"action['boxes'] must be real numbers, got dtype {boxes.dtype}")
        space = self.action_space["ids"]
        out = (ids < space.low[0]) | (ids > space.high[0])
        if out.any():
            raise ActionError(f"action['ids'] {ids[out][0]} is outside 0..{int(space.high[0])}")
        with np.errstate(over="ignore"):
            boxes = boxes.astype(self.action_space["boxes"].dtype)
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

    def remember_tracks(self, ids, boxes, debug: list[dict] | None = None, name: str | None = None):
        """Hand the env the tracks answering the current frame, with the tracker's `debug()` drawings and its name,
        for render() to draw on this frame (and record their trails). step() records its action's tracks itself,
        unless they were given here first for this frame: an agent that wants its drawings in `render()` or
        Gymnasium's RecordVideo calls `env.unwrapped.remember_tracks(tracks.ids, tracks.boxes, tracker.debug(),
        "name")` before `env.step(action)`. render() then shows the frame they answered until the next step."""
        if self._remembered_at == self.steps:
            return
        self._remembered_at = self.steps
        ids, boxes = np.asarray(ids, np.int64), np.asarray(boxes, float).reshape(-1, 4)
        self._last_tracks = (ids, boxes)
        if self.render_mode is not None:
            self._answered = (self.frame.copy(), self.truth, self.detections.rows.copy(), self.steps, list(debug or []),
                              name)
        centres = boxes[:, :2] + boxes[:, 2:] / 2
        for i, c in zip(ids.tolist(), centres):
            self._trails.setdefault(i, deque(maxlen=_TRAIL)).append(c)
        alive = set(ids.tolist())
        for i in [k for k in self._trails if k not in alive]:
            del self._trails[i]

    # ------------------------------------------------------------ rendering

    def render(self):
        """rgb_array: the frame the last tracks answered (the current one before any), enlarged render_scale times,
        with ground truth, detections, the tracks and any drawings their tracker handed over, a banner (frame,
        tracker, running MOTA / IDF1 / FP / FN / IDSW; IDF1 refreshed once a second of video) and a legend; human:
        show it in a window (which reset and step also do)."""
        if not self._started:
            raise RuntimeError("render() needs reset() first")
        if self.render_mode is None:
            gym.logger.warn("render() called with render_mode=None; make the env with render_mode='rgb_array'")
            return None
        frame, truth, dets, index, debug, name = self._answered or (self.frame, self.truth, self.detections.rows,
                                                                    self.steps, [], None)
        tracks = self._last_tracks if self._answered else (np.zeros(0, np.int64), np.zeros((0, 4)))
        img = draw_overlay(frame, truth, dets, *tracks, self._trails, self.render_scale)
        draw_debug(img, debug, self.render_scale)
        c = self.metrics.clear
        banner = f"frame {index}" + (f"  {name}" if name else "") + "  " + running_metrics(
            c.tp, c.fp, c.fn, c.idsw, self._running_idf1())
        draw_legend(draw_banner(img, banner))
        if self._viewer:
            self._viewer.show(img)
            return None
        return img

    def _running_idf1(self) -> float | None:
        """IDF1 so far, recomputed once per render_fps scored frames (it needs a global assignment)."""
        frames = len(self.metrics)
        if frames and (frames - self._idf1[0] >= self.metadata["render_fps"] or self._done):
            self._idf1 = (frames, self.metrics.summary()["IDF1"])
        return self._idf1[1]

    def close(self):
        if self._viewer:
            self._viewer.close()


def _get(config, dotted: str):
    """The value of a dotted key in a configuration, or None where it has no such key (a sequence has no render.*)."""
    obj = config
    for part in dotted.split("."):
        obj = getattr(obj, part, None)
    return obj
