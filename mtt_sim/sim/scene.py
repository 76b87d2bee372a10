"""A simulated scene as the env's source: the world moves, the renderer draws, the sensor detects.

It implements `mtt_sim.sources.Source`, the interface a recorded sequence implements too.
"""

from __future__ import annotations

import numpy as np

from mtt_sim.core.frame import Detections, ScoredTruth, Truth
from mtt_sim.core.settings import ConfigError
from mtt_sim.sim.camera import read_warps
from mtt_sim.sim.config import Scenario
from mtt_sim.sim.render import Renderer
from mtt_sim.sim.sensor import Sensor, make_sensor
from mtt_sim.sim.truth import measure
from mtt_sim.sim.world import World


class Scene:
    """One scenario's world, renderer and detector, rebuilt at every reset from the generators it is given."""

    length = None  # a scene ends when its world does (or at env.max_steps)
    scored = True
    detection_dtype = np.float32

    def __init__(self, scenario: Scenario):
        self.config = scenario
        self.frame_rate = scenario.world.frame_rate
        self.image_size = (scenario.render.width, scenario.render.height)
        self.world: World | None = None
        self.renderer: Renderer | None = None
        self.sensor: Sensor | None = None
        self.truth: Truth | None = None
        self.labels: np.ndarray | None = None
        self.trace = _trace(scenario)

    def detection_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Boxes lie in the image; confidences in conf_offset + [0, conf_scale] (and zero for padding rows)."""
        (w, h), s = self.image_size, self.config.sensor
        return (np.array([0, 0, 0, 0, min(s.conf_offset, 0.0)]),
                np.array([w, h, w, h, max(s.conf_offset + s.conf_scale, 0.0)]))

    def reset(self, world_rng: np.random.Generator, render_rng: np.random.Generator,
              sensor_rng: np.random.Generator) -> None:
        sc = self.config
        self.world = World(sc, world_rng)
        self.renderer = Renderer(sc, render_rng, self.trace)
        if sc.render.camera == "follow":
            self.renderer.camera.follow(self.world)
        empty = self.renderer.render(self.world, show_targets=False)[0] if sc.sensor.model == "foreground" else None
        self.sensor = make_sensor(sc, sensor_rng, empty)

    def observe(self, want_frame: bool) -> tuple[Truth, Detections, np.ndarray | None]:
        """Render the world as it is now (after reset, advance or `world.place`), measure its truth and detect."""
        frame, self.labels, boxes = self.renderer.render(self.world, draw_frame=want_frame)
        self.truth = self.measure(self.labels, boxes)
        return self.truth, self.sensor.detect(self.truth, self.labels, frame), frame

    def measure(self, labels: np.ndarray, boxes: np.ndarray) -> Truth:
        """The truth of the frame just rendered: the targets' image boxes, what of them the label map shows, and who
        covers whom."""
        w = self.world
        r = self.renderer
        return measure(labels, w.ids, boxes, w.depth(), w.shape_is_rect[w.group], r.occluder_image_boxes(),
                       r.occluder_depth, r.reference if r.warped else None)

    @property
    def camera_warp(self) -> np.ndarray:
        """The 2x3 warp that took the previous frame's pixel coordinates onto this frame's (BoT-SORT's GMC
        convention; the identity at the first frame and for a static camera)."""
        return np.array(self.renderer.camera.warp, float)

    def first_targets(self) -> tuple[np.ndarray, np.ndarray]:
        """Ids and boxes of the targets visible in the first frame (for trackers initialised by hand)."""
        seen = self.truth.visibility > 0
        return self.truth.ids[seen].copy(), self.truth.boxes[seen].copy()

    def scored_truth(self, track_boxes: np.ndarray) -> ScoredTruth:
        """The current frame's scored ground truth (ids, boxes), every track scored, and everyone in view (ids, boxes,
        visibility: the occlusion windows need the hidden targets too)."""
        t = self.truth
        scored = t.visibility >= self.config.scoring.min_visibility
        return ScoredTruth(t.ids[scored], t.boxes[scored], scored_tracks=slice(None),
                           in_view=(t.ids, t.boxes, t.visibility))

    def advance(self) -> None:
        self.world.step()
        self.renderer.camera.advance(self.world)

    @property
    def finished(self) -> bool:
        """No target is alive and none can be born any more."""
        return bool(self.world.finished)


def _trace(sc: Scenario) -> np.ndarray | None:
    """The warps a `trace` camera replays, read and checked once; None for other cameras. The camera's keys that
    cannot be checked one at a time are checked here."""
    r = sc.render
    if r.camera in ("trace", "walking") and sc.sensor.model == "foreground":
        raise ConfigError(f"sensor.model = 'foreground' needs a static, shaking or still camera, not render.camera = "
                          f"{r.camera!r}")
    if r.camera != "trace":
        return None
    if not r.trace:
        raise ConfigError("render.trace: render.camera = 'trace' needs a camera-motion file (BoT-SORT's GMC format)")
    try:
        warps = read_warps(r.trace)
    except ValueError as err:
        raise ConfigError(f"render.trace = {r.trace!r}: {err}") from None
    det = np.linalg.det(warps[:, :, :2])
    bad = np.flatnonzero(~(det > 1e-3))
    if len(bad):
        raise ConfigError(f"render.trace = {r.trace!r}: camera trace {r.trace}, frame {bad[0]}: the warp "
                          f"{warps[bad[0]].ravel().tolist()} flips or flattens the image (determinant {det[bad[0]]:g}; "
                          "a camera's is near 1)")
    return warps
