"""A scene fitted to a sequence's detections alone: `mtt-sim fit-scene`.

A camera without labels has only its detector's output, det/det.txt. Its detections are linked into tracklets by
SORT (min_hits=3, max_age=3) through the env, tracklets shorter than MIN_FRAMES are dropped, and the scene is fitted
to what they show (ground truth is never read, so gt/ may be missing or anything at all):
- image size, frame rate and length: seqinfo.ini (or what the detections imply); env.max_steps is the length;
- count: the mean number of tracklets per frame (the people in view at reset);
- size and far_scale: a least-squares line height = a + b y_bottom over every tracklet box, as the standing world
  draws people (height linear in the feet's row): size is (median aspect ratio x, 1 x) the height at the bottom row,
  far_scale the height at the top row over that, clipped to the schema's range (where clipped, the near height is
  refitted with far_scale held); no growth downward (b <= 0): a topdown world with the median box size;
- region: where the feet are, the 5th to 95th percentiles of the tracklets' foot points;
- speed: the median over tracklets of their net speed (net displacement over frames spanned, which box noise does
  not inflate), divided by the fitted depth scale at their mean feet row (the world gives the near speed);
  speed_jitter the relative spread of those speeds;
- heading: the tracklets' net directions; where most (> half) lie within 45 degrees of their circular mean, that
  mean with heading_jitter 45, else any direction (heading_jitter 180);
- how the people and the camera move (`mtt_sim.sim2real.fit_motion`): the scene runs at the sequence's frame rate
  (world.frame_rate), its people walk by the walking model (walk.model = "langevin", its keys fitted to the
  tracklets with the camera's common motion taken out, then refined by running the scene with its detector and
  linking its detections as the sequence's were, `fit_scene(refine=True)`), entering and leaving by doors at the
  left and right borders in the band of their feet (births: tracklet starts per frame after the first frame, shared
  by the entry doors; the group's own birth_rate is 0), and its camera is the walking camera model fitted to the
  common motion where the tracklets show one, else the still camera; the group's cv keys (speed, heading) stay, for
  walk.model = "off";
- the detector: the [sensor] table of a sensor file (`mtt-sim calibrate` on other, labelled sequences), its box
  noise and drift scaled to the sequence's own jitter by the refinement.
`statistics` measures the same on any tracklets, so the scene's own detections are checked against the sequence's
with one function.
"""

from __future__ import annotations

import dataclasses
import math
import shutil
import tempfile
import warnings
from pathlib import Path

import numpy as np

from mtt_sim.env import TrackingEnv
from mtt_sim.lab.episode import Episode
from mtt_sim.real.layout import is_sequence
from mtt_sim.sim import scenario as scn
from mtt_sim.sim2real import fit_motion

LINKER = "sort:min_hits=3,max_age=3"
MIN_FRAMES = 5       # tracklets shorter than this are dropped (false positives, fragments)
AGREE_DEG = 45.0     # headings within this of their mean agree
FAR_LIMIT = -5.0     # the lowest far_scale the schema allows (a horizon inside the picture)
MOVING = 0.2         # px/frame: slower tracklets have no heading
STAT_NAMES = {"people": "people per frame", "births": "births per frame", "height": "median height (px)",
              "far_near": "far/near height ratio", "speed": "median speed (px/frame)"}


def link(env, seed: int = 0, truth: list | None = None) -> np.ndarray:
    """SORT run over an env's own detections: (n, 6) rows frame, id, x, y, w, h of tracklets of MIN_FRAMES or more.
    Each frame's scored truth (ids, boxes) is appended to `truth` where it is given (a simulated scene's people)."""
    from mtt_sim import trackers

    rows, no_tracks = [], np.zeros((0, 4))
    for ep in Episode(env, seed, trackers.make(LINKER)):
        t = ep.tracks
        if t is not None and len(t):
            rows.append(np.column_stack([np.full(len(t), ep.steps), t.ids, t.boxes]))
        if truth is not None:
            scored = env.source.scored_truth(no_tracks)
            truth.append((scored.ids, scored.boxes))
    rows = np.concatenate(rows) if rows else np.zeros((0, 6))
    ids, counts = np.unique(rows[:, 1], return_counts=True)
    return rows[np.isin(rows[:, 1], ids[counts >= MIN_FRAMES])]


def link_sequence(folder, seed: int = 0) -> tuple[np.ndarray, object]:
    """The tracklets of a sequence folder and its info; only seqinfo.ini and det/det.txt are read (gt/ never is:
    they are linked into a scratch folder that holds nothing else)."""
    folder = Path(folder)
    if not is_sequence(folder) or not (folder / "det" / "det.txt").is_file():
        raise scn.ConfigError(f"{folder}: not a MOTChallenge sequence folder with det/det.txt")
    scratch = Path(tempfile.mkdtemp(prefix="fit_scene_"))
    try:
        (scratch / "det").mkdir()
        (scratch / "det" / "det.txt").symlink_to((folder / "det" / "det.txt").resolve())
        if (folder / "seqinfo.ini").is_file():
            (scratch / "seqinfo.ini").symlink_to((folder / "seqinfo.ini").resolve())
        with warnings.catch_warnings():  # unscored without gt/, as meant
            warnings.simplefilter("ignore")
            try:
                env = TrackingEnv(scratch, obs_mode="detections")
            except ValueError as err:  # a bad file named where the user has it, not in the scratch folder
                raise type(err)(str(err).replace(str(scratch), str(folder))) from None
        info = env.source.info  # named by seqinfo.ini, else after the scratch folder: then after the sequence's
        if not (folder / "seqinfo.ini").is_file():
            info = dataclasses.replace(info, name=folder.name)
        return link(env, seed), info
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def _tracklets(rows: np.ndarray):
    """Per tracklet (sorted by id): first frame, last frame, first and last centre, mean feet row."""
    order = np.lexsort((rows[:, 0], rows[:, 1]))
    r = rows[order]
    ids, first, counts = np.unique(r[:, 1], return_index=True, return_counts=True)
    last = first + counts - 1
    centre = r[:, 2:4] + r[:, 4:6] / 2
    feet = np.bincount(np.searchsorted(ids, r[:, 1]), r[:, 3] + r[:, 5]) / counts
    return r[first, 0], r[last, 0], centre[first], centre[last], feet


def _height_line(rows: np.ndarray) -> tuple[float, float]:
    """Least-squares a, b of height = a + b * y_bottom."""
    y = rows[:, 3] + rows[:, 5]
    if len(rows) < 2 or np.ptp(y) == 0:
        return (float(np.median(rows[:, 5])) if len(rows) else 0.0), 0.0
    b, a = np.polyfit(y, rows[:, 5], 1)
    return float(a), float(b)


def statistics(rows: np.ndarray, length: int, height: int) -> dict:
    """What the fit reads from tracklets, and the table compares: people and births per frame, median box height,
    height at the top row over height at the bottom row (the fitted line's, clipped as far_scale is), median net
    speed in the image."""
    if not len(rows):
        return {"people": 0.0, "births": 0.0, "height": 0.0, "far_near": 1.0, "speed": 0.0}
    start, end, c0, c1, _ = _tracklets(rows)
    a, b = _height_line(rows)
    near = a + b * height
    speed = np.linalg.norm(c1 - c0, axis=1) / np.maximum(end - start, 1)
    return {"people": len(rows) / length, "births": float(np.sum(start > 0)) / max(length - 1, 1),
            "height": float(np.median(rows[:, 5])),
            "far_near": float(np.clip(a / near, 0.05, 1.0)) if b > 0 and near > 0 else 1.0,
            "speed": float(np.median(speed))}


def fit(rows: np.ndarray, info) -> dict:
    """The scenario (as a nested mapping, without a sensor) that the tracklets `rows` of a sequence with `info`
    (width, height, frame_rate, length, name) imply; see the module's docstring for each estimate."""
    if not len(rows):
        raise scn.ConfigError(f"{info.name}: no tracklets of {MIN_FRAMES} frames or more in its detections")
    W, H, n = info.width, info.height, info.length
    st = statistics(rows, n, H)
    start, end, c0, c1, feet = _tracklets(rows)
    a, b = _height_line(rows)
    aspect = float(np.median(rows[:, 4] / rows[:, 5]))
    near = a + b * H
    standing = b > 0 and near > 0
    moved = fit_motion.fit(rows, info, float(np.clip(a / near, FAR_LIMIT, 0.999)) if standing else 1.0)
    if standing:
        # a camera going forward keeps the line's horizon, inside the picture where it is there: its flow is
        # measured from it; a still one keeps far_scale at 0.05 or more, the range the earlier fits had
        far = float(np.clip(a / near, FAR_LIMIT if "camera_forward" in moved["render"] else 0.05, 1.0))
        if far != a / near:  # clipped: the near height refitted (least squares) with far_scale held there
            g = far + (1.0 - far) * (rows[:, 3] + rows[:, 5]) / H
            near = float(g @ rows[:, 5] / (g @ g))
        scale = np.clip((a + b * feet) / near, max(far, 0.05), 1.0)
        size = (aspect * near, near)
        world = {"projection": "standing", "far_scale": far}
    else:
        scale = np.ones(len(start))
        size = (float(np.median(rows[:, 4])), float(np.median(rows[:, 5])))
        world = {"projection": "topdown"}
    net = c1 - c0
    speeds = np.linalg.norm(net, axis=1) / np.maximum(end - start, 1) / scale
    foot = np.column_stack([rows[:, 2] + rows[:, 4] / 2, rows[:, 3] + rows[:, 5]]) / [W, H]
    region = np.clip(np.percentile(foot, [5, 95], axis=0), 0.0, 1.0).ravel().tolist()  # x0, y0, x1, y1
    if region[2] - region[0] < 0.01 or region[3] - region[1] < 0.01:
        region = [0.0, 0.0, 1.0, 1.0]
    heading, jitter = _heading(net[speeds * scale >= MOVING])
    births = min(st["births"], 100.0)
    group = {"name": "people", "count": int(round(st["people"])), "birth_rate": 0.0,
             "region": [round(float(v), 3) for v in region], "size": [round(float(v), 1) for v in size],
             "motion": "cv", "speed": round(float(np.clip(np.median(speeds), 0.0, 200.0)), 3),
             "speed_jitter": round(float(np.clip(np.std(speeds) / max(np.mean(speeds), 1e-9), 0.0, 1.0)), 3),
             "heading": heading, "heading_jitter": jitter}
    doors = fit_motion.doors(W, H, size[1], (region[1], region[3]), heading if jitter < 180 else None, births,
                             ahead="camera_forward" in moved["render"])
    return {"name": _camel(info.name), "description": f"Fitted to the detections of {info.name} alone "
            "(mtt-sim fit-scene).", "world": {**world, **moved["world"]},
            "render": {"width": int(W), "height": int(H), **moved["render"]}, "walk": moved["walk"],
            "env": {"max_steps": int(n)}, "groups": [group], "doors": doors}


def _heading(net: np.ndarray) -> tuple[float, float]:
    """A dominant direction (deg) and 45, or 0 and 180 (any direction)."""
    if not len(net):
        return 0.0, 180.0
    theta = np.arctan2(net[:, 1], net[:, 0])
    mean = math.atan2(np.sin(theta).mean(), np.cos(theta).mean())
    off = np.abs((theta - mean + np.pi) % (2 * np.pi) - np.pi)
    if np.mean(off <= math.radians(AGREE_DEG)) > 0.5:
        return round(math.degrees(mean), 1), AGREE_DEG
    return 0.0, 180.0


def _camel(name: str) -> str:
    """A CamelCase scenario name from a sequence name (TUD-Campus: FittedTUDCampus)."""
    return "Fitted" + "".join(p[:1].upper() + p[1:] for p in "".join(c if c.isalnum() else " " for c in name).split())


def with_sensor(raw: dict, sensor) -> dict:
    """The scene with the [sensor] table of a sensor file, or with a mapping of sensor keys (none: the schema's
    default detector)."""
    if sensor is None:
        return raw
    return {**raw, **(scn.read_sensor(sensor) if isinstance(sensor, (str, Path)) else {"sensor": dict(sensor)})}


def scene_statistics(raw: dict, seeds=(0, 1)) -> dict:
    """The fitted scene's own detections, linked as the sequence's were, averaged over `seeds`."""
    sc = scn.from_mapping(raw, "fitted scene")
    stats = [statistics(link(TrackingEnv(sc, obs_mode="detections"), s), sc.env.max_steps, sc.render.height)
             for s in seeds]
    return {k: float(np.mean([s[k] for s in stats])) for k in STAT_NAMES}


def report(real: dict, scene: dict, name: str) -> str:
    """The sequence's statistics beside the fitted scene's, one a line."""
    lines = [f"{'statistic':26s} {name[:12]:>12s} {'fitted scene':>13s}"]
    lines += [f"{label:26s} {real[k]:12.3f} {scene[k]:13.3f}" for k, label in STAT_NAMES.items()]
    return "\n".join(lines)


def _scene_tracklets(raw: dict, seed: int) -> tuple[np.ndarray, list]:
    """The tracklets of one run of the scene `raw`, linked as a sequence's are, and its people (each frame's scored
    ids and boxes)."""
    truth: list = []
    return link(TrackingEnv(scn.from_mapping(raw, "fitted scene"), obs_mode="detections"), seed, truth), truth


def fit_scene(folder, sensor=None, seeds=(0, 1), refine: bool = True) -> tuple[dict, dict, dict, str]:
    """Fit a scene to a sequence folder's detections, with the detector `sensor` (a sensor file or a mapping of sensor
    keys): (the scene as a mapping with the sensor merged in, the sequence's statistics, the scene's statistics over
    `seeds`, the TOML text with its header)."""
    rows, info = link_sequence(folder)
    if not len(rows):
        raise scn.ConfigError(f"{folder}: no tracklets of {MIN_FRAMES} frames or more in its det/det.txt to fit a "
                              "scene to")
    raw = with_sensor(fit(rows, info), sensor)
    scn.from_mapping(raw, f"scene fitted to {folder}")
    if refine:
        raw = fit_motion.refine(raw, fit_motion.tracklet_motion(rows, info.length, info.frame_rate), _scene_tracklets,
                                info.length, info.frame_rate)[0]
    real = statistics(rows, info.length, info.height)
    scene = scene_statistics(raw, seeds) if seeds else {}
    header = [f"mtt-sim fit-scene: a scene fitted to the detections of {Path(folder).name} alone",
              f"({info.length} frames at {info.frame_rate:g} fps; {len(np.unique(rows[:, 1]))} tracklets of at least "
              f"{MIN_FRAMES} frames linked by {LINKER}).",
              "Detector: " + ("the default." if sensor is None else f"the [sensor] table of {Path(sensor).name}."
                              if isinstance(sensor, (str, Path)) else "the one given."),
              f"Motion: walkers by walk.model = \"langevin\" at {info.frame_rate:g} fps; a {raw['render']['camera']} "
              "camera" + (" (the tracklets' common motion)" if raw["render"]["camera"] == "walking" else "")
              + (f", going forward ({raw['render']['camera_forward']:g}/s: the tracklets grow and slide outward)"
                 if raw["render"].get("camera_forward") else "")
              + (f", {raw['render']['camera_companions']} people walking along with it (they hold still in the picture)"
                 if raw["render"].get("camera_companions") else "") + ".",
              "See mtt_sim/sim2real/fit_scene.py for each estimate."]
    return raw, real, scene, scn.to_toml(raw, header)
