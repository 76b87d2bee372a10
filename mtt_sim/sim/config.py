"""The scenario's schema: typed, frozen dataclasses, one per TOML table.

The tables a recorded sequence shares (the detector, the Gym face, the scoring) and `setting`, the field whose
metadata documents and constrains a key, live below both sources in `mtt_sim.core.settings`; the validator in
`mtt_sim.core.validate` checks them all, and `mtt_sim.sim.scenario.reference_table` turns them into the
configuration reference.
"""

from __future__ import annotations

from dataclasses import dataclass

from mtt_sim.core import settings
from mtt_sim.core.moved import moved
from mtt_sim.core.settings import EnvConfig, ScoringConfig, SensorConfig, setting, table

__getattr__ = moved(__name__, settings, "ConfigError", "PRESETS")  # deprecated: import them from mtt_sim.core.settings

Color = tuple[int, int, int]
Rect = tuple[float, float, float, float]

MOTIONS = ("cv", "random_walk", "manoeuvre", "goal", "carried")
TEXTURES = ("none", "stripes", "checks", "noise")


@dataclass(frozen=True)
class GroupConfig:
    """One kind of target: its look, its motion model and how many there are."""

    name: str = setting("targets", "group name (other groups refer to it, e.g. as carrier)")
    count: int = setting(4, "targets placed at reset", "targets", 0, 10000)
    birth_rate: float = setting(0.0, "Poisson births per frame at the world borders, entering inward", "1/frame", 0.0, 100.0)
    region: Rect = setting((0.0, 0.0, 1.0, 1.0), "where initial targets are placed: x0, y0, x1, y1 as fractions of the world", "fraction", 0.0, 1.0)
    shape: str = setting("ellipse", "drawn outline; the physics footprint is a circle (ellipse) or a box (rect)", choices=("ellipse", "rect"))
    size: tuple[float, float] = setting((24.0, 24.0), "drawn width, height (standing: at the near edge of the image)", "px", 1.0, 2000.0)
    size_jitter: float = setting(0.1, "relative standard deviation of each target's size", "", 0.0, 0.5)
    color: Color = setting((200, 60, 60), "base colour, RGB", "", 0, 255)
    similarity: float = setting(0.0, "0: every target gets a distinct random hue; 1: all share `color` exactly", "", 0.0, 1.0)
    texture: str = setting("none", "pattern drawn on the target so gradient features exist", choices=TEXTURES)
    gait: float = setting(0.0, "non-rigid deformation: relative amplitude of the periodic change of the axes", "", 0.0, 0.5)
    gait_period: float = setting(20.0, "period of the gait", "frames", 2.0, 1000.0)
    motion: str = setting("cv", "motion model: constant velocity with random acceleration, Brownian random walk, "
                       "manoeuvres (sudden turns and stops), goal-seeking toward an exit, carried by another target",
                       choices=MOTIONS)
    speed: float = setting(2.0, "mean initial speed (random_walk: velocity standard deviation per frame)", "px/frame", 0.0, 200.0)
    speed_jitter: float = setting(0.2, "relative standard deviation of the initial speed", "", 0.0, 1.0)
    heading: float = setting(0.0, "mean initial direction of travel, 0 = +x (right), 90 = +y (down)", "deg", -360.0, 360.0)
    heading_jitter: float = setting(180.0, "half-width of the uniform spread around `heading`; 180 = any direction", "deg", 0.0, 180.0)
    accel: float = setting(0.05, "standard deviation of the random acceleration (cv, manoeuvre, goal)", "px/frame^2", 0.0, 50.0)
    max_speed: float = setting(20.0, "speeds are clipped to this", "px/frame", 0.1, 500.0)
    turn_prob: float = setting(0.02, "manoeuvre: probability per frame of a sudden turn by 60..180 deg", "1/frame", 0.0, 1.0)
    stop_prob: float = setting(0.01, "manoeuvre: probability per frame of stopping, and of a stopped target starting again x5", "1/frame", 0.0, 1.0)
    layer: int = setting(0, "topdown: targets on different layers do not collide; higher layers are drawn on top", "", 0, 15)
    carrier: str = setting("", "carried: name of the group whose targets carry these (one each, pinned by a joint)")


@dataclass(frozen=True)
class DoorConfig:
    """A place inside the scene where targets appear (entry) or disappear (exit)."""

    rect: Rect = setting((0.0, 0.0, 10.0, 10.0), "x, y, w, h in world coordinates", "px", -1e5, 1e5)
    role: str = setting("both", "entry: spawns targets; exit: absorbs goal-seeking and passing targets; both", choices=("entry", "exit", "both"))
    birth_rate: float = setting(0.0, "Poisson births per frame from this door", "1/frame", 0.0, 100.0)
    group: str = setting("", "group of the targets it spawns (default: the first group)")


@dataclass(frozen=True)
class OccluderConfig:
    """A static object (pillar, tree, wall) drawn in front of the targets behind it."""

    rect: Rect = setting((0.0, 0.0, 10.0, 10.0), "x, y, w, h in world coordinates", "px", -1e5, 1e5)
    shape: str = setting("rect", "drawn outline", choices=("rect", "ellipse"))
    color: Color = setting((90, 90, 90), "RGB", "", 0, 255)
    solid: bool = setting(False, "targets collide with it (topdown: its area; standing: its base line)")


@dataclass(frozen=True)
class WalkConfig:
    """People who walk like people (`mtt_sim.sim.walkers`): a Langevin velocity relaxing toward a desired velocity
    toward the goal, with stops; in body heights and seconds. The defaults are fitted to the still cameras of MOT17-02
    and MOT17-09 (`mtt-sim motion SEQ... --fit FILE`)."""

    model: str = setting("off", "off: every group moves by its own `motion`; langevin: every group not carried walks by "
                         "this model instead (one key switches a scene between the two)", choices=("off", "langevin"))
    speed: float = setting(0.32, "median desired walking speed", "heights/s", 0.0, 10.0)
    speed_jitter: float = setting(0.54, "spread of the desired speeds between people (log-normal sigma)", "", 0.0, 2.0)
    relax: float = setting(1.0, "time the velocity takes to relax toward the desired one", "s", 0.01, 100.0)
    noise: float = setting(0.079, "strength of the velocity noise", "heights/s/sqrt(s)", 0.0, 10.0)
    stand_noise: float = setting(10.0, "how many times weaker the noise is while a person stands", "", 1.0, 1000.0)
    stop_rate: float = setting(0.131, "rate at which a walking person stops", "1/s", 0.0, 100.0)
    go_rate: float = setting(0.184, "rate at which a standing person walks on", "1/s", 0.0, 100.0)


@dataclass(frozen=True)
class WorldConfig:
    """The pymunk world: its size, projection, walls, collisions and population limits."""

    projection: str = setting("topdown", "topdown: the image is the world plane; standing: the world is the ground plane "
                           "and targets are upright blobs that shrink with distance", choices=("topdown", "standing"))
    size: tuple[float, float] = setting((0.0, 0.0), "world width, height; 0 = the image size (larger for a panning camera)", "px", 0.0, 1e5)
    walls: bool = setting(False, "targets bounce off the world borders instead of leaving")
    collision: str = setting("elastic", "target-target contacts: elastic, soft (inelastic) or none", choices=("elastic", "soft", "none"))
    max_alive: int = setting(1000, "no births while this many targets are alive (at most the label map's 65535)", "targets", 1,
                          65535)
    max_births: int = setting(-1, "total births over the episode, -1 = unlimited", "targets", -1, 1000000)
    far_scale: float = setting(0.4, "standing: size factor at the top of the world relative to the bottom; below 0 the "
                               "horizon lies inside the world, at the row where it is 0 (a camera at people's height)",
                               "", -5.0, 1.0)
    frame_rate: float = setting(25.0, "frames per second of the simulated video: the walking model's seconds and the "
                                "env's clock follow it (the other motion keys are per frame)", "1/s", 1.0, 240.0)
    carry_frames: int = setting(0, "topdown: a target completely covered by a moving target of a higher layer rides with it "
                                "for this many frames and is then left where it is (Liu et al.'s Fig. 14: a book carried under another); 0 = never",
                             "frames", 0, 100000)


@dataclass(frozen=True)
class RenderConfig:
    """How a frame looks: resolution, background, lighting, noise and camera."""

    width: int = setting(640, "image width", "px", 16, 4096)
    height: int = setting(480, "image height", "px", 16, 4096)
    background: str = setting("noise", "flat colour, textured noise, or clutter of target-like blobs", choices=("flat", "noise", "clutter"))
    background_color: Color = setting((110, 120, 110), "RGB", "", 0, 255)
    background_blobs: int = setting(40, "clutter background: number of static blobs", "", 0, 10000)
    brightness: float = setting(1.0, "global gain; below 1 is a dark scene", "", 0.05, 3.0)
    illumination_drift: float = setting(0.0, "relative amplitude of a slow sinusoidal gain drift", "", 0.0, 0.9)
    illumination_period: float = setting(200.0, "period of the drift", "frames", 2.0, 1e6)
    flicker: float = setting(0.0, "standard deviation of a per-frame relative gain jitter", "", 0.0, 0.5)
    noise: float = setting(0.0, "Gaussian pixel noise standard deviation", "grey levels", 0.0, 100.0)
    blur: float = setting(0.0, "Gaussian blur sigma (0 = none)", "px", 0.0, 20.0)
    camera: str = setting("static", "static; pan: sweeps across a larger world; follow: keeps the targets' mean centred; "
                       "shake: handheld jitter; trace: replays the camera-motion file `trace`; walking: a camera "
                       "carried along, its motion drawn from a model fitted to real walking and driving cameras; "
                       "still: a camera on a tripod, its jitter fitted to real ones (docs/camera_motion.md)",
                       choices=("static", "pan", "follow", "shake", "trace", "walking", "still"))
    pan_speed: tuple[float, float] = setting((2.0, 0.0), "pan: camera velocity, reversing at the world's edges; follow: its "
                                          "largest speed", "px/frame", -100.0, 100.0)
    shake: float = setting(3.0, "shake: standard deviation of the camera offset", "px", 0.0, 100.0)
    trace: str = setting("", "trace: a camera-motion file in BoT-SORT's GMC format (a line a frame: its 0-based index, "
                         "then the 2x3 warp a00 a01 a02 a10 a11 a12 from the previous frame's pixels onto this one's), "
                         "replayed from the middle of the world, frame k with line k; past its last line the camera "
                         "holds its last pose. A relative path is the scenario file's folder's, else the working "
                         "directory's")
    camera_step: tuple[float, float] = setting((0.00067, 0.00061), "walking: spread of the camera's shift a frame, "
                                               "across and down (a Student-t scale; see camera_tail)", "width/frame",
                                               0.0, 0.2)
    camera_step_corr: tuple[float, float] = setting((0.862, 0.087), "walking: frame-to-frame correlation of that shift, "
                                                    "across and down (AR(1))", "", 0.0, 0.999)
    camera_turn: float = setting(0.0609, "walking: spread of the camera's roll a frame", "deg/frame", 0.0, 10.0)
    camera_turn_corr: float = setting(0.02, "walking: frame-to-frame correlation of the roll", "", 0.0, 0.999)
    camera_zoom: float = setting(0.098, "walking: spread of the camera's scale change a frame (walking forward and "
                                 "back)", "%/frame", 0.0, 10.0)
    camera_zoom_corr: float = setting(0.747, "walking: frame-to-frame correlation of the scale change", "", 0.0, 0.999)
    camera_tail: float = setting(1.1, "walking: Student-t degrees of freedom of the motion's innovations (small: heavy "
                                 "tails, a camera mostly slow and at times fast; 1000: Gaussian; a draw is capped at "
                                 "50 scales)", "", 1.0, 1000.0)
    camera_return: float = setting(40.0, "walking and still: a spring pulls the camera back toward its rest pose, "
                                   "with a period of about 2 pi times this, so that it stays over the world",
                                   "frames", 1.0, 1e6)
    still_jitter: float = setting(2.74e-05, "still: spread of the camera's shift a frame, either way (a Student-t scale)",
                                  "width/frame", 0.0, 0.01)
    still_jitter_corr: float = setting(0.258, "still: frame-to-frame correlation of that shift", "", 0.0, 0.999)
    still_tail: float = setting(1.8, "still: Student-t degrees of freedom of the jitter's innovations", "", 1.0, 1000.0)
    camera_forward: float = setting(0.0, "standing: the camera is driven or carried forward over the ground, and "
                                    "everyone on it flows out from the horizon's middle as in a pinhole camera moving "
                                    "along its axis: the rate at which a person at the bottom row grows (a person at "
                                    "depth factor s grows s times as fast); 0 = not at all (mtt_sim/sim/forward.py)",
                                    "1/s", 0.0, 5.0)
    camera_companions: int = setting(0, "going forward: people who walk with the camera (a cameraman's companions, "
                                     "walking ahead at its pace), placed at reset abreast about the middle column, "
                                     "who keep their place in the picture: the ground's flow does not move them, and "
                                     "walkers among them stand", "people", 0, 20)


@dataclass(frozen=True)
class Scenario:
    """A named scenario: everything needed to build and run one episode."""

    name: str = setting("Custom", "CamelCase name; the env id is mtt_sim/<name>-v0")
    description: str = setting("", "one paragraph: what it models and which experiment it mirrors")
    world: WorldConfig = table(WorldConfig, "the pymunk world")
    walk: WalkConfig = table(WalkConfig, "the walking model")
    render: RenderConfig = table(RenderConfig, "the frame")
    sensor: SensorConfig = table(SensorConfig, "the detector")
    env: EnvConfig = table(EnvConfig, "the Gym face")
    scoring: ScoringConfig = table(ScoringConfig, "scoring and rewards")
    groups: tuple[GroupConfig, ...] = setting((GroupConfig(),), "target groups ([[groups]] tables)")
    doors: tuple[DoorConfig, ...] = setting((), "entry/exit doors ([[doors]] tables)")
    occluders: tuple[OccluderConfig, ...] = setting((), "static occluders ([[occluders]] tables)")

    @property
    def world_size(self) -> tuple[float, float]:
        """World width and height in pixels (the image size where `world.size` is 0)."""
        w, h = self.world.size
        return (w or float(self.render.width), h or float(self.render.height))

    def group(self, name: str) -> int:
        """Index of the group called `name`."""
        names = [g.name for g in self.groups]
        return names.index(name)
