"""Scenario configuration: typed, frozen, validated dataclasses loaded from TOML.

Every field carries its meaning, unit and allowed values in ``metadata``; one generic
validator turns a nested mapping into a :class:`Scenario` and rejects unknown keys, wrong
types and out-of-range values with a message naming the source, the dotted key, the value
and what is allowed. The same metadata generates the README's configuration reference.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import math
import tomllib
import typing
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Mapping

import numpy as np


class ConfigError(ValueError):
    """A scenario file or override is invalid; the message names file, key, value and what is allowed."""


def spec(default, doc, unit="", lo=None, hi=None, choices=None):
    """A dataclass field whose metadata documents and constrains it."""
    meta = {"doc": doc, "unit": unit, "lo": lo, "hi": hi, "choices": choices}
    if isinstance(default, (list, tuple)) and default and dataclasses.is_dataclass(default[0]):
        return field(default_factory=lambda: tuple(default), metadata=meta)
    return field(default=default, metadata=meta)


def table(cls, doc):
    """A nested dataclass field (a TOML table)."""
    return field(default_factory=cls, metadata={"doc": doc})


Color = tuple[int, int, int]
Rect = tuple[float, float, float, float]

MOTIONS = ("cv", "random_walk", "manoeuvre", "goal", "carried")
TEXTURES = ("none", "stripes", "checks", "noise")


@dataclass(frozen=True)
class GroupConfig:
    """One kind of target: its look, its motion model and how many there are."""

    name: str = spec("targets", "group name (other groups refer to it, e.g. as carrier)")
    count: int = spec(4, "targets placed at reset", "targets", 0, 10000)
    birth_rate: float = spec(0.0, "Poisson births per frame at the world borders, entering inward", "1/frame", 0.0, 100.0)
    region: Rect = spec((0.0, 0.0, 1.0, 1.0), "where initial targets are placed: x0, y0, x1, y1 as fractions of the world", "fraction", 0.0, 1.0)
    shape: str = spec("ellipse", "drawn outline; the physics footprint is a circle (ellipse) or a box (rect)", choices=("ellipse", "rect"))
    size: tuple[float, float] = spec((24.0, 24.0), "drawn width, height (standing: at the near edge of the image)", "px", 1.0, 2000.0)
    size_jitter: float = spec(0.1, "relative standard deviation of each target's size", "", 0.0, 0.5)
    color: Color = spec((200, 60, 60), "base colour, RGB", "", 0, 255)
    similarity: float = spec(0.0, "0: every target gets a distinct random hue; 1: all share `color` exactly", "", 0.0, 1.0)
    texture: str = spec("none", "pattern drawn on the target so gradient features exist", choices=TEXTURES)
    gait: float = spec(0.0, "non-rigid deformation: relative amplitude of the periodic change of the axes", "", 0.0, 0.5)
    gait_period: float = spec(20.0, "period of the gait", "frames", 2.0, 1000.0)
    motion: str = spec("cv", "motion model: constant velocity with random acceleration, Brownian random walk, "
                       "manoeuvres (sudden turns and stops), goal-seeking toward an exit, carried by another target",
                       choices=MOTIONS)
    speed: float = spec(2.0, "mean initial speed (random_walk: velocity standard deviation per frame)", "px/frame", 0.0, 200.0)
    speed_jitter: float = spec(0.2, "relative standard deviation of the initial speed", "", 0.0, 1.0)
    heading: float = spec(0.0, "mean initial direction of travel, 0 = +x (right), 90 = +y (down)", "deg", -360.0, 360.0)
    heading_jitter: float = spec(180.0, "half-width of the uniform spread around `heading`; 180 = any direction", "deg", 0.0, 180.0)
    accel: float = spec(0.05, "standard deviation of the random acceleration (cv, manoeuvre, goal)", "px/frame^2", 0.0, 50.0)
    max_speed: float = spec(20.0, "speeds are clipped to this", "px/frame", 0.1, 500.0)
    turn_prob: float = spec(0.02, "manoeuvre: probability per frame of a sudden turn by 60..180 deg", "1/frame", 0.0, 1.0)
    stop_prob: float = spec(0.01, "manoeuvre: probability per frame of stopping, and of a stopped target starting again x5", "1/frame", 0.0, 1.0)
    layer: int = spec(0, "topdown: targets on different layers do not collide; higher layers are drawn on top", "", 0, 15)
    carrier: str = spec("", "carried: name of the group whose targets carry these (one each, pinned by a joint)")


@dataclass(frozen=True)
class DoorConfig:
    """A place inside the scene where targets appear (entry) or disappear (exit)."""

    rect: Rect = spec((0.0, 0.0, 10.0, 10.0), "x, y, w, h in world coordinates", "px", -1e5, 1e5)
    role: str = spec("both", "entry: spawns targets; exit: absorbs goal-seeking and passing targets; both", choices=("entry", "exit", "both"))
    birth_rate: float = spec(0.0, "Poisson births per frame from this door", "1/frame", 0.0, 100.0)
    group: str = spec("", "group of the targets it spawns (default: the first group)")


@dataclass(frozen=True)
class OccluderConfig:
    """A static object (pillar, tree, wall) drawn in front of the targets behind it."""

    rect: Rect = spec((0.0, 0.0, 10.0, 10.0), "x, y, w, h in world coordinates", "px", -1e5, 1e5)
    shape: str = spec("rect", "drawn outline", choices=("rect", "ellipse"))
    color: Color = spec((90, 90, 90), "RGB", "", 0, 255)
    solid: bool = spec(False, "targets collide with it (topdown: its area; standing: its base line)")


@dataclass(frozen=True)
class WorldConfig:
    """The pymunk world: its size, projection, walls, collisions and population limits."""

    projection: str = spec("topdown", "topdown: the image is the world plane; standing: the world is the ground plane "
                           "and targets are upright blobs that shrink with distance", choices=("topdown", "standing"))
    size: tuple[float, float] = spec((0.0, 0.0), "world width, height; 0 = the image size (larger for a panning camera)", "px", 0.0, 1e5)
    walls: bool = spec(False, "targets bounce off the world borders instead of leaving")
    collision: str = spec("elastic", "target-target contacts: elastic, soft (inelastic) or none", choices=("elastic", "soft", "none"))
    max_alive: int = spec(1000, "no births while this many targets are alive (at most the label map's 65535)", "targets", 1,
                          65535)
    max_births: int = spec(-1, "total births over the episode, -1 = unlimited", "targets", -1, 1000000)
    far_scale: float = spec(0.4, "standing: size factor at the top of the world relative to the bottom", "", 0.05, 1.0)
    carry_frames: int = spec(0, "topdown: a target completely covered by a moving target of a higher layer rides with it "
                                "for this many frames and is then left where it is (seed 002's Fig. 14); 0 = never",
                             "frames", 0, 100000)


@dataclass(frozen=True)
class RenderConfig:
    """How a frame looks: resolution, background, lighting, noise and camera."""

    width: int = spec(640, "image width", "px", 16, 4096)
    height: int = spec(480, "image height", "px", 16, 4096)
    background: str = spec("noise", "flat colour, textured noise, or clutter of target-like blobs", choices=("flat", "noise", "clutter"))
    background_color: Color = spec((110, 120, 110), "RGB", "", 0, 255)
    background_blobs: int = spec(40, "clutter background: number of static blobs", "", 0, 10000)
    brightness: float = spec(1.0, "global gain; below 1 is a dark scene", "", 0.05, 3.0)
    illumination_drift: float = spec(0.0, "relative amplitude of a slow sinusoidal gain drift", "", 0.0, 0.9)
    illumination_period: float = spec(200.0, "period of the drift", "frames", 2.0, 1e6)
    flicker: float = spec(0.0, "standard deviation of a per-frame relative gain jitter", "", 0.0, 0.5)
    noise: float = spec(0.0, "Gaussian pixel noise standard deviation", "grey levels", 0.0, 100.0)
    blur: float = spec(0.0, "Gaussian blur sigma (0 = none)", "px", 0.0, 20.0)
    camera: str = spec("static", "static; pan: sweeps across a larger world; follow: keeps the targets' mean centred; "
                       "shake: handheld jitter", choices=("static", "pan", "follow", "shake"))
    pan_speed: tuple[float, float] = spec((2.0, 0.0), "pan: camera velocity, reversing at the world's edges; follow: its "
                                          "largest speed", "px/frame", -100.0, 100.0)
    shake: float = spec(3.0, "shake: standard deviation of the camera offset", "px", 0.0, 100.0)


def _fitted_detectors() -> dict[str, dict[str, Any]]:
    """The fitted detectors shipped as mtt_sim/detectors/<name>.toml, each a [sensor] table whose header says what it
    is fitted to; `model` and `memory` stay the scenario's own."""
    out = {}
    for entry in sorted(resources.files("mtt_sim").joinpath("detectors").iterdir(), key=lambda p: p.name):
        if entry.name.endswith(".toml"):
            table = tomllib.loads(entry.read_text())["sensor"]
            out[entry.name[:-5]] = {k: v for k, v in table.items() if k not in ("model", "memory")}
    return out


PRESETS: dict[str, dict[str, Any]] = {
    "ideal": dict(pd=1.0, min_visibility=0.0, box_noise=0.0, box_size_noise=0.0, box_drift=0.0, box_outlier_prob=0.0,
                  box_outlier_persist=0.0, box_scale=1.0, fragment_prob=0.0, merge_prob=0.0, clutter_rate=0.0,
                  site_rate=0.0, conf_true=0.95, conf_false=0.3),
    **_fitted_detectors(),
}


@dataclass(frozen=True)
class SensorConfig:
    """The simulated detector. Keys given explicitly override the chosen preset's values.

    `synthetic` detects a target with a probability logistic in its visible fraction and height, raised after a
    detection and lowered after a miss (`miss_corr`); boxes carry per-frame noise, occasional outliers and a per-target
    drift; false positives are fresh clutter plus persistent sites; confidences are Beta-distributed by source.
    """

    model: str = spec("synthetic", "synthetic: from the truth and the label map; foreground: background subtraction on "
                      "the frame; recorded: a sequence folder's det/det.txt (its default; synthetic replays its ground "
                      "truth through the synthetic detector instead)", choices=("synthetic", "foreground", "recorded"))
    preset: str = spec("", "fill the keys below from a detector preset (docs/detectors.md: what each is fitted to)",
                       choices=("",) + tuple(PRESETS))
    memory: bool = spec(True, "errors persist: misses follow each target's last outcome, boxes drift, false-positive "
                        "sites last site_life frames; false: every frame drawn independently with the same rates")
    pd: float = spec(0.95, "P(detect) of a fully visible target at least reference_height tall (its recall over time)", "",
                     0.0, 1.0)
    miss_corr: float = spec(0.5, "frame-to-frame correlation of a target's misses: P(detect) is P + (1 - P) miss_corr "
                            "after a detection and P (1 - miss_corr) after a miss", "", 0.0, 0.999)
    pd_spread: float = spec(0.0, "spread of each target's own ease of detection, drawn once: N(0, pd_spread) on the "
                            "logit of P(detect) (some people are found in almost every frame, some hardly ever)",
                            "logit", 0.0, 10.0)
    visibility_slope: float = spec(4.0, "logit of P(detect) gained per unit of visible fraction", "logit", 0.0, 100.0)
    height_slope: float = spec(0.0, "logit of P(detect) lost per halving of the box height below reference_height",
                               "logit", -10.0, 10.0)
    reference_height: float = spec(100.0, "box height from which pd holds (taller is no easier)", "px", 1.0, 1e4)
    min_visibility: float = spec(0.2, "never detected at or below this visible fraction", "", 0.0, 1.0)
    box_noise: float = spec(0.03, "per-frame noise of the box centre, across and down, in units of the box's scale "
                            "sqrt(w h) (standard deviation)", "", 0.0, 1.0)
    box_size_noise: float = spec(0.03, "per-frame noise of the box width and height, in units of sqrt(w h)", "",
                                 0.0, 1.0)
    box_drift: float = spec(0.0, "per-target drift of the box centre, AR(1) with this stationary standard deviation "
                            "(units of sqrt(w h)), on top of the per-frame noise", "", 0.0, 1.0)
    box_size_drift: float = spec(0.0, "the same for the box width and height", "", 0.0, 1.0)
    box_drift_corr: float = spec(0.9, "frame-to-frame correlation of the box drift", "", 0.0, 0.999)
    box_outlier_prob: float = spec(0.0, "probability a detection's box is an outlier (IoU 0.3-0.5 with its target's) "
                                   "when the target's last box was good", "", 0.0, 1.0)
    box_outlier_persist: float = spec(0.0, "the same when its last box was an outlier, or it was missed or new (poor "
                                      "boxes persist, and a target coming back is often boxed poorly)", "", 0.0, 1.0)
    box_outlier_noise: float = spec(0.3, "spread of outlier boxes and of sites held beside a target (units of "
                                    "sqrt(w h))", "", 0.01, 2.0)
    box_scale: float = spec(1.0, "systematic box enlargement (loose boxes > 1)", "", 0.5, 2.0)
    box_aspect: float = spec(1.0, "systematic widening relative to the height (> 1: boxes too wide)", "", 0.25, 4.0)
    fragment_prob: float = spec(0.02, "probability a visible target is reported as 2-3 fragments "
                                "(always when an occluder cuts it apart)", "", 0.0, 1.0)
    merge_prob: float = spec(0.5, "probability targets whose visible regions touch are reported as one box", "", 0.0, 1.0)
    clutter_rate: float = spec(0.5, "Poisson mean of fresh false detections per frame (each lasts one frame)", "1/frame",
                               0.0, 1000.0)
    site_rate: float = spec(0.0, "Poisson mean of persistent false-alarm sites born per frame", "1/frame", 0.0, 100.0)
    site_life: float = spec(10.0, "mean life of a site (geometric; it fires every frame it lives)", "frames", 1.0, 1e5)
    site_near: float = spec(0.5, "share of sites born beside a visible target (IoU 0.1-0.3 with it), moving with it "
                            "(double and partial boxes); the rest are static background boxes", "", 0.0, 1.0)
    conf_true: float = spec(0.85, "mean confidence of a detection of a fully visible target at least reference_height tall",
                            "", 0.01, 0.99)
    conf_visibility: float = spec(2.0, "logit of the mean true confidence gained per unit of visible fraction",
                                  "logit", 0.0, 100.0)
    conf_height: float = spec(0.0, "logit of the mean true confidence lost per halving of the box height below "
                              "reference_height", "logit", -10.0, 10.0)
    conf_false: float = spec(0.35, "mean confidence of a false detection", "", 0.01, 0.99)
    conf_spread: float = spec(8.0, "Beta concentration of the true confidences (higher = tighter)", "", 0.5, 1e4)
    conf_false_spread: float = spec(0.0, "Beta concentration of the false confidences (0 = conf_spread)", "", 0.0, 1e4)
    conf_offset: float = spec(0.0, "reported confidence = conf_offset + conf_scale * Beta draw (raw scores like DPM's)",
                              "", -1e4, 1e4)
    conf_scale: float = spec(1.0, "see conf_offset", "", 1e-6, 1e4)
    min_area: float = spec(20.0, "foreground: smallest blob kept", "px^2", 0.0, 1e6)
    threshold: float = spec(25.0, "foreground: grey-level difference that counts as foreground", "grey levels", 1.0, 255.0)
    learning_rate: float = spec(0.02, "foreground: background model update rate on background pixels", "", 0.0, 1.0)
    max_detections: int = spec(256, "observation rows; extra detections (lowest confidence first) are dropped", "", 1, 100000)


@dataclass(frozen=True)
class EnvConfig:
    """The Gym face: episode length, action size and what the observation holds."""

    max_steps: int = spec(300, "episode length; truncated after this many steps", "steps", 1, 10**7)
    max_tracks: int = spec(256, "rows of the action's padded track arrays", "", 1, 100000)
    obs_mode: str = spec("frame+detections", "detections: no frame in the observation (no rendering cost beyond the label map)",
                         choices=("frame+detections", "detections"))


@dataclass(frozen=True)
class ScoringConfig:
    """How tracks are scored against ground truth: the matching, the GOSPA parameters and the per-step reward."""

    similarity: str = spec("iou", "iou: box overlap; centroid: max(0, 1 - centre distance / zero_distance)",
                           choices=("iou", "centroid"))
    threshold: float = spec(0.5, "a track matches a target when their similarity is at least this (CLEAR, IDF1)", "", 0.01, 1.0)
    zero_distance: float = spec(20.0, "centroid similarity reaches 0 at this centre distance", "px", 0.1, 1e5)
    gospa_c: float = spec(50.0, "GOSPA cut-off distance (a miss or a false track costs c/2)", "px", 0.1, 1e5)
    gospa_p: float = spec(1.0, "GOSPA order", "", 1.0, 10.0)
    min_visibility: float = spec(0.0, "targets less visible than this are not scored (0 = every target in the image)", "", 0.0, 1.0)
    reward_mode: str = spec("mota", "mota: TP - FP - IDSW (return / GT boxes = MOTA); gospa: -GOSPA of the frame; "
                            "iou: iou_weight * summed IoU of matches - fp_weight * FP - fn_weight * FN",
                            choices=("mota", "gospa", "iou"))
    iou_weight: float = spec(1.0, "reward_mode iou: weight of the matched similarity", "", 0.0, 1e3)
    fp_weight: float = spec(1.0, "reward_mode iou: cost of a false track", "", 0.0, 1e3)
    fn_weight: float = spec(1.0, "reward_mode iou: cost of a missed target", "", 0.0, 1e3)


@dataclass(frozen=True)
class Scenario:
    """A named scenario: everything needed to build and run one episode."""

    name: str = spec("Custom", "CamelCase name; the env id is mtt_sim/<name>-v0")
    description: str = spec("", "one paragraph: what it models and which experiment it mirrors")
    world: WorldConfig = table(WorldConfig, "the pymunk world")
    render: RenderConfig = table(RenderConfig, "the frame")
    sensor: SensorConfig = table(SensorConfig, "the detector")
    env: EnvConfig = table(EnvConfig, "the Gym face")
    scoring: ScoringConfig = table(ScoringConfig, "scoring and rewards")
    groups: tuple[GroupConfig, ...] = spec((GroupConfig(),), "target groups ([[groups]] tables)")
    doors: tuple[DoorConfig, ...] = spec((), "entry/exit doors ([[doors]] tables)")
    occluders: tuple[OccluderConfig, ...] = spec((), "static occluders ([[occluders]] tables)")

    @property
    def world_size(self) -> tuple[float, float]:
        """World width and height in pixels (the image size where `world.size` is 0)."""
        w, h = self.world.size
        return (w or float(self.render.width), h or float(self.render.height))

    def group(self, name: str) -> int:
        """Index of the group called `name`."""
        names = [g.name for g in self.groups]
        return names.index(name)


# ---------------------------------------------------------------- building from mappings

def _type_name(tp) -> str:
    return getattr(tp, "__name__", str(tp))


def _convert(value, tp, key: str, meta: Mapping, where: str):
    """Check `value` against annotation `tp` and the field's range/choices; return the typed value."""

    given = value

    def fail(allowed: str):
        raise ConfigError(f"{where}: {key} = {given!r}: {allowed}")

    if isinstance(value, (np.generic, np.ndarray)):  # numpy numbers and arrays are numbers and lists
        value = value.tolist()
    origin = typing.get_origin(tp)
    if dataclasses.is_dataclass(tp):
        if not isinstance(value, Mapping):
            fail(f"expected a table of {tp.__name__} keys")
        return _build(tp, value, where, key + ".")
    if origin is tuple:
        args = typing.get_args(tp)
        if not isinstance(value, (list, tuple)):
            fail(f"expected a list ({_describe(tp)})")
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(v, args[0], f"{key}.{i}", meta, where) for i, v in enumerate(value))
        if len(value) != len(args):
            fail(f"expected {len(args)} values ({_describe(tp)})")
        return tuple(_convert(v, a, f"{key}.{i}", meta, where) for i, (v, a) in enumerate(zip(value, args)))
    if tp is bool:
        if not isinstance(value, bool):
            fail("expected true or false")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            fail("expected an integer" + _range_text(meta))
    elif tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(_as_float(value)):
            fail("expected a finite number" + _range_text(meta))
        value = float(value)
    elif tp is str:
        if not isinstance(value, str):
            fail("expected a string")
    if meta.get("choices") is not None and value not in meta["choices"]:
        fail(f"allowed values: {', '.join(repr(c) for c in meta['choices'])}")
    lo, hi = meta.get("lo"), meta.get("hi")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        fail("out of range" + _range_text(meta))
    return value


def _as_float(value: int | float) -> float:
    """float(value), with an integer too large for a float read as infinite (so it fails as not finite)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf


def _range_text(meta: Mapping) -> str:
    lo, hi = meta.get("lo"), meta.get("hi")
    if lo is None and hi is None:
        return ""
    return f"; allowed: {'-inf' if lo is None else lo} <= value <= {'inf' if hi is None else hi}"


def _describe(tp) -> str:
    if typing.get_origin(tp) is tuple:
        args = typing.get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis:
            return f"list of {_describe(args[0])}"
        return f"{len(args)} x {_type_name(args[0])}"
    return _type_name(tp)


_HINTS: dict[type, dict[str, Any]] = {}


def _hints(cls) -> dict[str, Any]:
    if cls not in _HINTS:
        _HINTS[cls] = typing.get_type_hints(cls)
    return _HINTS[cls]


def _build(cls, raw: Mapping, where: str, prefix: str = ""):
    """Construct dataclass `cls` from mapping `raw`, validating every key."""
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(raw) - set(fields), key=str)
    if unknown:
        near = difflib.get_close_matches(str(unknown[0]), fields, n=1)
        raise ConfigError(f"{where}: unknown key {prefix}{unknown[0]}" + (f" (did you mean {prefix}{near[0]}?)" if near
                          else "") + f"; allowed keys: {', '.join(fields)}")
    hints = _hints(cls)
    values = {name: _convert(raw[name], hints[name], prefix + name, fields[name].metadata, where)
              for name in fields if name in raw}
    return cls(**values)


def _with_preset(raw: Mapping, where: str) -> dict:
    """Fill sensor keys from the named preset under the explicitly given ones."""
    raw = dict(raw)
    sensor = raw.get("sensor")
    if isinstance(sensor, Mapping) and sensor.get("preset"):
        if sensor["preset"] not in PRESETS:
            raise ConfigError(f"{where}: sensor.preset = {sensor['preset']!r}: allowed values: {', '.join(map(repr, PRESETS))}")
        raw["sensor"] = {**PRESETS[sensor["preset"]], **sensor}
    return raw


def _check_references(sc: Scenario, where: str) -> Scenario:
    """Cross-field rules that a single field's range cannot express."""
    names = [g.name for g in sc.groups]
    if len(set(names)) != len(names):
        raise ConfigError(f"{where}: groups: names must be unique, got {names}")
    if not sc.groups:
        raise ConfigError(f"{where}: groups: at least one [[groups]] table is required")
    for i, g in enumerate(sc.groups):
        if g.motion == "carried":
            if g.carrier not in names or g.carrier == g.name:
                raise ConfigError(f"{where}: groups.{i}.carrier = {g.carrier!r}: must name another group, one of {names}")
            if g.birth_rate > 0:
                raise ConfigError(f"{where}: groups.{i}.birth_rate: carried targets are only placed at reset")
        x0, y0, x1, y1 = g.region
        if x1 <= x0 or y1 <= y0:
            raise ConfigError(f"{where}: groups.{i}.region = {g.region}: need x0 < x1 and y0 < y1")
    for i, d in enumerate(sc.doors):
        if d.group and d.group not in names:
            raise ConfigError(f"{where}: doors.{i}.group = {d.group!r}: allowed values: {names}")
    ww, wh = sc.world_size
    if ww < sc.render.width or wh < sc.render.height:
        raise ConfigError(f"{where}: world.size = {sc.world.size}: must be at least the image size "
                          f"({sc.render.width}, {sc.render.height}) or 0")
    if sc.sensor.model == "foreground" and sc.render.camera in ("pan", "follow"):
        raise ConfigError(f"{where}: sensor.model = 'foreground' needs a static or shaking camera, not render.camera = "
                          f"{sc.render.camera!r}")
    return _check_budget(sc, where)


LABEL_MAX = 65535  # the uint16 label map holds slot + 1 of every target alive
MEMORY_BUDGET = 4 * 2**30  # bytes; a scenario estimated to need more is refused before anything is allocated


def memory_estimate(sc: Scenario) -> int:
    """Bytes an episode of `sc` needs at its peak, roughly: the world backdrop (about 100 bytes a pixel while its
    noise is made in float64, 3 once done), each image pixel's frame, label map, noise bank and detector model
    (40 bytes), and each target's arrays and pymunk body (2 KB)."""
    ww, wh = sc.world_size
    margin = 8 * sc.render.shake if sc.render.camera == "shake" else 0.0
    world_px = (ww + margin) * (wh + margin)
    image_px = sc.render.width * sc.render.height
    per_world_px = 3 if sc.render.background == "flat" else 100
    return int(world_px * per_world_px + image_px * 40 + sum(g.count for g in sc.groups) * 2048)


def _check_budget(sc: Scenario, where: str) -> Scenario:
    """Totals no single field's range bounds: targets against the label map's range, the memory an episode needs."""
    total = sum(g.count for g in sc.groups)
    if total > LABEL_MAX:
        counts = " + ".join(str(g.count) for g in sc.groups)
        raise ConfigError(f"{where}: groups[].count: {counts} = {total} targets at reset; at most {LABEL_MAX} can be "
                          "alive at once (the uint16 label map's range)")
    need = memory_estimate(sc)
    if need > MEMORY_BUDGET:
        ww, wh = sc.world_size
        raise ConfigError(f"{where}: this scenario would need about {need / 2**30:.1f} GiB (world.size {ww:g} x {wh:g} "
                          f"px, image {sc.render.width} x {sc.render.height} px, {total} targets); the budget is "
                          f"{MEMORY_BUDGET / 2**30:.0f} GiB: make the world or the image smaller")
    return sc


def from_mapping(raw: Mapping, where: str = "<config>") -> Scenario:
    """Build and validate a Scenario from a nested mapping (as read from TOML)."""
    if not isinstance(raw, Mapping):
        raise ConfigError(f"{where}: expected a table of scenario keys, got {type(raw).__name__}")
    raw = _with_preset(raw, where)
    return _check_references(_build(Scenario, raw, where), where)


# ---------------------------------------------------------------- files and overrides

def scenario_dir():
    """The folder of shipped scenario files: package data `mtt_sim.scenarios`, or `scenarios/` in a source checkout."""
    try:
        return resources.files("mtt_sim.scenarios")
    except ModuleNotFoundError:
        return Path(__file__).resolve().parent.parent / "scenarios"


def available() -> dict[str, str]:
    """Shipped scenario keys (file stems) mapped to the first sentence of their description."""
    out = {}
    for entry in sorted(scenario_dir().iterdir(), key=lambda p: p.name):
        if entry.name.endswith(".toml"):
            desc = load_raw(entry.name[:-5])[0].get("description", "")
            out[entry.name[:-5]] = desc.split(". ")[0].strip().rstrip(".")
    return out


@functools.cache
def shipped_names() -> dict[str, str]:
    """Shipped scenario keys mapped to their CamelCase names (the env id of key k is mtt_sim/<name>-v0)."""
    return {p.name[:-5]: tomllib.loads(p.read_text()).get("name", "Custom")
            for p in sorted(scenario_dir().iterdir(), key=lambda p: p.name) if p.name.endswith(".toml")}


def is_sequence(path) -> bool:
    """Whether `path` is a folder laid out as a MOTChallenge sequence (seqinfo.ini, det/det.txt or gt/gt.txt)."""
    p = Path(path)
    return p.is_dir() and any((p / f).is_file() for f in ("seqinfo.ini", "det/det.txt", "gt/gt.txt"))


def resolve(name: str | Path) -> str | Path:
    """The shipped key a user means, in any letter case or as its env id ("mtt_sim/Crossing-v0"); a .toml file or a
    recorded sequence's folder is returned as a Path. An unknown name gets the list of keys and, for a near miss, a
    suggestion."""
    if Path(name).is_dir():
        if not is_sequence(name):
            raise ConfigError(f"{str(name)!r} is a folder but not a MOTChallenge sequence (no seqinfo.ini, det/det.txt "
                              "or gt/gt.txt in it)")
        return Path(name)
    if isinstance(name, Path) or str(name).endswith(".toml"):
        if not Path(name).is_file():
            raise ConfigError(f"scenario file {str(name)!r}: not found")
        return Path(name)
    keys = shipped_names()
    spellings = {k.lower(): k for k in keys} | {f"mtt_sim/{n}-v0".lower(): k for k, n in keys.items()}
    typed = str(name).strip().lower()
    if typed in spellings:
        return spellings[typed]
    near = difflib.get_close_matches(typed, spellings, n=1, cutoff=0.7)
    raise ConfigError(f"unknown scenario {str(name)!r}" + (f" (did you mean {spellings[near[0]]!r}?)" if near else "")
                      + f"; available: {', '.join(keys)} (in any case, or their env ids, a .toml file or a sequence folder)")


def load_raw(key_or_path: str | Path, seen: tuple[str, ...] = ()) -> tuple[dict, str]:
    """Read a scenario's TOML mapping by shipped key (see `resolve`) or file path; returns (mapping, where).
    A file with `base = "<scenario>"` is that scenario's mapping with the file's keys merged over it (a variant)."""
    found = resolve(key_or_path)
    if isinstance(found, Path):
        text, where = found.read_text(), str(found)
    else:
        text, where = (scenario_dir() / f"{found}.toml").read_text(), f"scenarios/{found}.toml"
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise ConfigError(f"{where}: invalid TOML: {err}") from None
    if "base" not in raw:
        return raw, where
    base = raw.pop("base")
    if not isinstance(base, str) or base in seen:
        raise ConfigError(f"{where}: base = {base!r}: expected the name of another scenario, without a cycle")
    try:
        return merge(load_raw(base, (*seen, str(found)))[0], raw), where
    except ConfigError as err:
        raise ConfigError(f"{where}: base = {base!r}: {err}") from None


def expand_dotted(overrides: Mapping, prefix: str = "") -> dict:
    """Turn {"sensor.pd": 0.5} and nested dicts alike, or any mix of the two, into one nested dict.

    Integer keys are list indices ({"groups": {0: {...}}} is "groups.0..."). A value given twice (say as
    "sensor.pd" and inside "sensor") is an error, never silently dropped.
    """
    if not isinstance(overrides, Mapping):
        raise ConfigError(f"config overrides must be a mapping of keys to values, got {type(overrides).__name__}")
    out: dict = {}
    for key, value in overrides.items():
        if isinstance(key, int) and not isinstance(key, bool):
            key = str(key)
        if not isinstance(key, str) or not key or "" in key.split("."):
            raise ConfigError(f"override key {prefix}{key!r}: keys are dotted names such as 'sensor.pd'")
        node, path = out, prefix
        *parents, leaf = key.split(".")
        for part in parents:
            path += part + "."
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise ConfigError(f"override {path.rstrip('.')} is given both as a value and as a table of keys")
        if isinstance(value, Mapping):
            value = expand_dotted(value, f"{path}{leaf}.")
        _put(node, leaf, value, path)
    return out


def _put(node: dict, key: str, value, prefix: str) -> None:
    """node[key] = value, merging tables and refusing a second value for the same key."""
    if key not in node:
        node[key] = value
    elif isinstance(node[key], dict) and isinstance(value, dict):
        for k, v in value.items():
            _put(node[key], k, v, f"{prefix}{key}.")
    else:
        raise ConfigError(f"override {prefix}{key} is given twice (e.g. as a dotted key and inside a table); give it once")


def merge(base: Mapping, overrides: Mapping, prefix: str = "") -> dict:
    """Recursively merge `overrides` into `base`; list items are addressed by index ("groups.0.count",
    "groups.0.size.0")."""
    out = dict(base)
    for key, value in overrides.items():
        out[key] = _merged(out.get(key), value, f"{prefix}{key}")
    return out


def _merged(current, value, path: str):
    if isinstance(current, Mapping) and isinstance(value, Mapping):
        return merge(current, value, path + ".")
    if isinstance(current, (list, tuple)) and isinstance(value, Mapping):
        items = list(current)
        for idx, sub in value.items():
            if not (isinstance(idx, str) and idx.isdigit() and int(idx) < len(items)):
                raise ConfigError(f"override {path}.{idx}: no such item; {path} has {len(items)} entries")
            items[int(idx)] = _merged(items[int(idx)], sub, f"{path}.{idx}")
        return items
    return value


def to_mapping(obj) -> Any:
    """A Scenario (or part) as plain nested dicts and lists, the inverse of `from_mapping`."""
    if dataclasses.is_dataclass(obj):
        return {f.name: to_mapping(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, tuple):
        return [to_mapping(x) for x in obj]
    return obj


def load(key_or_path: str | Path | Scenario, overrides: Mapping | None = None) -> Scenario:
    """Load a shipped scenario (by key), a TOML file or an existing Scenario, with optional overrides."""
    if isinstance(key_or_path, Scenario):
        raw, where = to_mapping(key_or_path), f"scenario {key_or_path.name}"
    elif is_sequence(key_or_path):
        from .sequence import Recording  # here: the recorded source builds on this module

        return Recording(key_or_path).scenario(overrides)
    else:
        raw, where = load_raw(key_or_path)
    if overrides:
        if not isinstance(overrides, Mapping):
            raise ConfigError(f"config overrides must be a mapping, got {type(overrides).__name__}")
        try:
            raw = merge(raw, expand_dotted(overrides))
        except ConfigError as err:
            raise ConfigError(f"{where}: {err}") from None
        where += " (with overrides)"
    sc = from_mapping(raw, where)
    if sc.sensor.model == "recorded":
        raise ConfigError(f"{where}: sensor.model = 'recorded' replays a sequence folder's det/det.txt; a scenario's "
                          "detector is 'synthetic' or 'foreground'")
    return sc


def read_sensor(path: str | Path) -> dict:
    """The [sensor] table of a TOML file (as `mtt-sim calibrate` writes), to be merged into a scenario's overrides."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"{path}: no such sensor file (a TOML file with a [sensor] table, e.g. from mtt-sim calibrate)")
    try:
        table = tomllib.loads(path.read_text()).get("sensor")
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as err:
        raise ConfigError(f"{path}: invalid TOML: {err}") from None
    if not isinstance(table, Mapping):
        raise ConfigError(f"{path}: expected a [sensor] table")
    return {"sensor": dict(table)}


def reference_table() -> str:
    """Markdown table of every configuration key: key, default, unit, allowed values, meaning."""
    rows = ["| key | default | unit | allowed | meaning |", "|---|---|---|---|---|"]

    def walk(cls, prefix):
        hints = _hints(cls)
        for f in dataclasses.fields(cls):
            tp, meta = hints[f.name], f.metadata
            inner = typing.get_args(tp)[0] if typing.get_origin(tp) is tuple else None
            if dataclasses.is_dataclass(tp):
                walk(tp, prefix + f.name + ".")
                continue
            if inner is not None and dataclasses.is_dataclass(inner):
                walk(inner, f"{prefix}{f.name}[].")
                continue
            default = f.default if f.default is not dataclasses.MISSING else f.default_factory()
            if meta.get("choices"):
                allowed = ", ".join(repr(c) for c in meta["choices"])
            else:
                allowed = _range_text(meta).replace("; allowed: ", "")
            rows.append(f"| `{prefix}{f.name}` | `{default!r}` | {meta.get('unit', '')} | {allowed} | {meta.get('doc', '')} |")

    walk(Scenario, "")
    rows += ["", f"Totals: at most {LABEL_MAX} targets at reset (the sum of `groups[].count`, the uint16 label map's "
                 f"range), and an estimated peak memory (`mtt_sim.scenario.memory_estimate`) of at most "
                 f"{MEMORY_BUDGET // 2**30} GiB, which bounds `world.size` times the image size."]
    return "\n".join(rows)


__all__ = ["Scenario", "GroupConfig", "DoorConfig", "OccluderConfig", "WorldConfig", "RenderConfig", "SensorConfig",
           "EnvConfig", "ScoringConfig", "ConfigError", "PRESETS", "available", "load", "load_raw", "from_mapping", "to_mapping",
           "merge", "expand_dotted", "reference_table", "resolve", "shipped_names"]

