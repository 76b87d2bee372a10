"""How a fitted scene moves, from a sequence's tracklets alone (`mtt-sim fit-scene`; issue 38, item 4).

The tracklets (SORT's boxes over the detections) move for two reasons: the people walk, and the camera moves under
them. The camera's motion is common to every tracklet in a frame; the people's is their own. The fit tells them apart,
then fits each model to its share:

- the camera's shift a frame: the median displacement of the feet of the tracklets seen in this frame and the last
  (robust to the few that walk, switch or jump). That median is the camera's only where the camera moves: on a still
  camera it is the people's own common drift (a crowd walking one way) and box noise. So the shift is kept only where
  the data show a common motion that no walker makes: the frame-to-frame changes of the tracklets' displacements
  (their accelerations over EVIDENCE_LAG seconds), split at random into two halves per frame, have medians that
  agree from frame to frame (split-half correlation at least MOVING_R, and significant: Fisher z at least MOVING_Z;
  and not below MIN_COMMON px, under which no tracker would see it)
  where a camera shakes, walks or turns, and do not where only people move (each person's changes are their own and
  the box noise is each box's own). Where too few tracklets overlap to tell, the camera is taken as still;
- a moving camera: the walking camera model (`mtt_sim.sim.camera.fit`) fitted to those shifts as a trace (translation
  only: the roll and the scale change of a frame are below what a few noisy boxes show, so the model's are zero),
  its spread scaled down to the common motion's share of the per-frame medians (their reliability, from the split
  halves' correlation: the rest is the boxes' noise);
  a still one: the still camera model as shipped (a tripod's jitter, fitted to real still cameras, far below box
  noise);
- the walkers: the walking model (`walk.model = "langevin"`) fitted to the tracklets with the camera's shift taken
  out, in body heights and seconds at the sequence's frame rate, as `fit_walkers.fit` fits it to ground truth: the
  stop and go rates, the desired speed and its spread read off directly (where no stop or no start is seen, the rates
  from the standing share), the relaxation time and the noise (and the desired speed) chosen by simulating the
  model's walkers alone. Those are the people as the tracklets show them, box noise included: a detector's boxes
  jitter and drift by a few percent of a height a frame, which over a one-second constant-velocity guess is as
  large as real people's own deviation from it on a still camera (fitted so, the walkers came out 1.5-2.5 times too
  unpredictable on the still MOT15 cameras), and smoothing the tracklets does not take it out (the drift lasts for
  many frames). So `refine` then runs the scene itself with its detector, links its detections by SORT as the
  sequence's were, and sets the detector's box noise, the walkers' stop rate and noise so that the scene's tracklets
  show the sequence's tracklets' jitter, standing share and deviation: like against like, noise, fragments and
  camera on both sides;
- where they come and go (`doors`): entries and exits at the left and right borders in the band of the feet, on the
  sides the tracklets come from and go to.
"""

from __future__ import annotations

import math
from dataclasses import asdict, replace

import numpy as np

from mtt_sim.sim import camera as cam
from mtt_sim.sim import scenario as scn
from mtt_sim.sim.config import WalkConfig
from mtt_sim.sim2real import fit_forward, fit_jitter
from mtt_sim.sim2real import fit_walkers as walkers_fit
from mtt_sim.sim2real.motion import STANDING, track_rows, window_values

EVIDENCE_LAG = 0.2   # s: the lag of the accelerations whose common part is the camera's
MOVING_R = 0.2       # split-half correlation of the common accelerations from which the camera moves
MOVING_Z = 3.0       # ... and its Fisher z (a correlation this far from none by chance is rare)
MIN_COMMON = 0.2     # px: ... and the common acceleration's size (its root mean square over the frames, both axes)
SPLITS = 10          # random splits averaged
MIN_SPLIT_FRAMES = 20  # frames with four tracklets or more that the camera's evidence needs
MIN_WINDOWS = 100     # two-second stretches of tracklets the walkers' relaxation and noise need
SIM_PEOPLE, SIM_SECONDS = 60, 15.0  # the walkers simulated for each try of the fit
REFINE_WINDOWS = 2000  # one-second windows of the scene's tracklets each run of the refinement pools over seeds ...
MAX_SEEDS = 12        # ... taking at most this many (a short sequence's scene gives few windows a seed)
LIMITS = {"noise": (0.005, 10.0), "stop_rate": (0.01, 100.0),
          "speed": tuple(scn.setting_of("walk.speed")[1][end] for end in ("lo", "hi"))}
REACH = {"noise": 10.0, "stop_rate": 10.0, "speed": 3.0}  # the refinement moves each at most this far from the fit
NOISE_KEYS = fit_jitter.KEYS  # the detector's frame-to-frame noise, scaled to the jitter as calibrate matches it
NOISE_REACH = 4.0     # ... at most this far either way
SIDEWAYS = math.cos(math.radians(45))  # a heading whose cosine is beyond this walks across (left or right)
WALK_KEYS = ("model", "speed", "speed_jitter", "relax", "noise", "stand_noise", "stop_rate", "go_rate")


def frames_of(rows: np.ndarray, length: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Tracklet rows (frame, id, x, y, w, h; frames from 0) as `length` frames of (ids, boxes)."""
    rows = rows[np.argsort(rows[:, 0], kind="stable")]
    cut = np.searchsorted(rows[:, 0], np.arange(length + 1))
    return [(rows[a:b, 1].astype(np.int64), rows[a:b, 2:6]) for a, b in zip(cut[:-1], cut[1:])]


def frames_from_tracks(tracks: dict[int, np.ndarray], length: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per-id (frame, foot x, foot y, height) rows (`motion.track_rows`) back as frames of (ids, boxes), the boxes
    0.4 heights wide about the foot point."""
    ids, boxes, at = [], [], []
    for i, r in tracks.items():
        ids.append(np.full(len(r), i))
        at.append(r[:, 0].astype(int))
        h = r[:, 3]
        boxes.append(np.c_[r[:, 1] - 0.2 * h, r[:, 2] - h, 0.4 * h, h])
    if not ids:
        return [(np.zeros(0, np.int64), np.zeros((0, 4)))] * length
    ids, boxes, at = np.concatenate(ids), np.concatenate(boxes), np.concatenate(at)
    order = np.argsort(at, kind="stable")
    cut = np.searchsorted(at[order], np.arange(length + 1))
    return [(ids[order[a:b]], boxes[order[a:b]]) for a, b in zip(cut[:-1], cut[1:])]


def _per_frame(tracks: dict[int, np.ndarray], length: int, lag: int) -> list[np.ndarray]:
    """Per frame k, the (m, 2) second differences at `lag` of the foot points of the tracks through k - 2 lag .. k
    (lag 0: the displacements from k - 1 to k)."""
    out: list[list] = [[] for _ in range(length)]
    for r in tracks.values():
        feet, k = r[:, 1:3], r[:, 0].astype(int)
        if lag == 0:
            if len(r) < 2:
                continue
            values, at = feet[1:] - feet[:-1], k[1:]
        else:
            if len(r) <= 2 * lag:
                continue
            values, at = feet[2 * lag:] - 2 * feet[lag:-lag] + feet[:-2 * lag], k[2 * lag:]
        for j, v in zip(at, values):
            out[j].append(v)
    return [np.array(v).reshape(-1, 2) for v in out]


def common_shift(tracks: dict[int, np.ndarray], length: int) -> tuple[np.ndarray, np.ndarray]:
    """Per frame, the median displacement (px) of the foot points of the tracks seen in it and the frame before, and
    how many there were; frames with fewer than two take the shift interpolated from their neighbours (0 at the
    ends), the first frame none."""
    moves = _per_frame(tracks, length, 0)
    count = np.array([len(m) for m in moves])
    shift = np.zeros((length, 2))
    known = np.flatnonzero(count >= 2)
    if len(known):
        med = np.array([np.median(moves[k], axis=0) for k in known])
        for c in (0, 1):
            shift[:, c] = np.interp(np.arange(length), known, med[:, c], left=0.0, right=0.0)
    shift[0] = 0.0
    return shift, count


def camera_evidence(tracks: dict[int, np.ndarray], length: int, frame_rate: float, seed: int = 0) -> dict:
    """How strongly the tracklets share a common motion that changes: the split-half correlation of the per-frame
    medians of their accelerations over EVIDENCE_LAG seconds (both axes, averaged over SPLITS random splits), its
    Fisher z, the frames it rests on and the size of the common acceleration (px, the root mean square of the
    per-frame medians' length)."""
    lag = max(1, round(EVIDENCE_LAG * frame_rate))
    acc = [a for a in _per_frame(tracks, length, lag) if len(a) >= 4]
    if len(acc) < MIN_SPLIT_FRAMES:
        return {"r": 0.0, "z": 0.0, "frames": len(acc), "common": 0.0}
    common = float(np.sqrt(np.mean([np.median(a, axis=0) ** 2 for a in acc]) * 2))
    rng = np.random.default_rng(seed)
    rs = []
    for _ in range(SPLITS):
        halves = []
        for a in acc:
            p = rng.permutation(len(a))
            h = len(a) // 2
            halves.append((np.median(a[p[:h]], axis=0), np.median(a[p[h:2 * h]], axis=0)))
        a, b = np.array(halves).transpose(1, 0, 2)
        per_axis = [np.corrcoef(a[:, c], b[:, c])[0, 1] for c in (0, 1) if np.std(a[:, c]) > 0 and np.std(b[:, c]) > 0]
        rs.append(np.mean(per_axis) if per_axis else 0.0)
    r = float(np.clip(np.mean(rs), -0.999, 0.999))
    return {"r": r, "z": float(math.atanh(r) * math.sqrt(len(acc) - 3)), "frames": len(acc), "common": common}


def stabilise(tracks: dict[int, np.ndarray], shift: np.ndarray) -> dict[int, np.ndarray]:
    """The tracks with the camera's path (its shifts summed) taken out of their foot points."""
    path = np.cumsum(shift, axis=0)
    out = {}
    for i, r in tracks.items():
        r = r.copy()
        r[:, 1:3] -= path[r[:, 0].astype(int)]
        out[i] = r
    return out


def fit_walkers(frames, frame_rate: float, seed: int = 0) -> WalkConfig:
    """The walking model whose walkers show the statistics of `frames` at `frame_rate`: `fit_walkers.fit`'s grid and
    refinement (the same code path, its parameters clipped to the schema's ranges)."""
    values = window_values(frames, frame_rate)
    try:
        direct = walkers_fit.direct([(frames, frame_rate)])
    except ValueError:  # nobody walks a whole second: the shipped desired speed
        direct = {}
    base = replace(WalkConfig(model="langevin"), **direct)
    if not direct or base.stop_rate <= 0 or base.go_rate <= 0:  # no stop or no start seen
        base = replace(base, **_rates_from_share(frames, frame_rate))
    if len(values["deviation"]) < MIN_WINDOWS:  # too short to read the relaxation and the noise: the shipped ones
        return base
    target = walkers_fit.statistics([values])

    def with_(relax: float, walk_noise: float, speed: float) -> WalkConfig:
        return replace(base, relax=float(np.clip(relax, 0.01, 100.0)), noise=float(np.clip(walk_noise, 0.0, 10.0)),
                       speed=float(np.clip(speed, 0.0, 10.0)))

    return with_(*walkers_fit.search(with_, base.speed, target, frame_rate, SIM_PEOPLE, SIM_SECONDS, seed))


def _rates_from_share(frames, frame_rate: float) -> dict:
    """Stop and go rates where the tracklets show no stop or no start (people who stand, or walk, for the whole of
    their short tracklets): a standing spell about twice the median tracklet (it outlasts the tracklets), and the stop
    rate that keeps the tracklets' standing share of whole seconds."""
    per_track = walkers_fit.seconds(frames, frame_rate)
    if not per_track:
        return {}
    standing = float(np.mean(np.concatenate(per_track) < STANDING))
    go = 1.0 / (2.0 * max(1.0, float(np.median([len(s) for s in per_track]))))
    return {"go_rate": round(go, 4), "stop_rate": round(min(go * standing / max(1 - standing, 0.05), 100.0), 4)}


def fit(rows: np.ndarray, info, far_scale: float = 1.0) -> dict:
    """The motion of the scene fitted to tracklet rows (frame, id, x, y, w, h) of a sequence with `info` (width,
    height, frame_rate, length), seen as a ground with `far_scale` (1: none in perspective, so no forward motion):
    {"world": {"frame_rate"}, "walk": the walking model's keys, "render": the camera's keys, "camera": what was
    estimated (the evidence, the per-frame shifts, whether it moves; the forward evidence)}."""
    rate, length = float(info.frame_rate), int(info.length)
    frames = frames_of(rows, length)
    tracks = track_rows(frames)
    ahead, pulled, along = 0.0, 0.0, 0  # forward first: its flow is no common shift, nor does a walker's speed hold it
    if far_scale < 1.0:
        values = fit_forward.windows(tracks, info.width, rate)
        pulled = fit_forward.evidence(values)
        if pulled >= fit_forward.MOVING_R:
            ahead = round(fit_forward.rate(values, info.height, far_scale), 4)
            along = fit_forward.companions(window_values(frames, rate)["speed"], length, rate)
            tracks = fit_forward.without(tracks, (info.width, info.height), far_scale, ahead, rate)
    shift, count = common_shift(tracks, length)
    evidence = camera_evidence(tracks, length, rate)
    moving = evidence["r"] >= MOVING_R and evidence["z"] >= MOVING_Z and evidence["common"] >= MIN_COMMON
    if moving:
        tracks = stabilise(tracks, shift)
        warps = np.repeat(cam.IDENTITY[None], length, axis=0)
        warps[1:, :, 2] = shift[1:]
        keys = cam.fit([(warps, info.width, info.height)])
        # the per-frame median carries the boxes' noise too: the model's spread is the common motion's share of it,
        # the full median's reliability from the split halves' correlation (Spearman-Brown)
        share = math.sqrt(min(1.0, 2 * evidence["r"] / (1 + evidence["r"])))
        keys["camera_step"] = [round(v * share, 6) for v in keys["camera_step"]]
        render = {"camera": "walking", **keys, "camera_turn": 0.0, "camera_zoom": 0.0}
    else:
        shift = np.zeros_like(shift)
        render = {"camera": "still"}
    if ahead > 0:
        render["camera_forward"] = ahead
        if along:
            render["camera_companions"] = along
    walkers = fit_walkers(frames_from_tracks(tracks, length), rate)
    walk = {k: (round(v, 4) if isinstance(v, float) else v) for k, v in asdict(walkers).items() if k in WALK_KEYS}
    return {"world": {"frame_rate": rate}, "walk": walk, "render": render,
            "camera": {**evidence, "moving": bool(moving), "shift": shift, "overlaps": count, "forward_r": pulled}}


def tracklet_motion(rows: np.ndarray, length: int, frame_rate: float) -> np.ndarray:
    """The median speed, the median one-second deviation (heights), the standing share (as `motion.people` measures
    them), the median jitter (`jitters`), the median walking speed (of the windows at STANDING or faster) and the
    number of windows of tracklet rows (nan where there is none)."""
    frames = frames_of(rows, length)
    return _measured(window_values(frames, frame_rate), jitters(frames))


def jitters(frames) -> np.ndarray:
    """Each tracked foot point's second difference over consecutive frames, in heights: the boxes' frame-to-frame
    jitter, which is the detector's far more than the people's (a walker's change of velocity in one frame is small)."""
    out = [np.hypot(*(r[2:, 1:3] - 2 * r[1:-1, 1:3] + r[:-2, 1:3]).T) / r[1:-1, 3]
           for r in track_rows(frames).values() if len(r) >= 3]
    return np.concatenate(out) if out else np.zeros(0)


def _measured(values: dict, jitter: np.ndarray) -> np.ndarray:
    """The median speed and deviation and the standing share of `motion.window_values`' values, the median
    `jitter`, the median walking speed and the number of windows."""
    med = lambda v: float(np.median(v)) if len(v) else float("nan")  # noqa: E731
    speed = values["speed"]
    return np.array([med(speed), med(values["deviation"]),
                     float(np.mean(speed < STANDING)) if len(speed) else float("nan"), med(jitter),
                     med(speed[speed >= STANDING]), len(values["deviation"])])


def refine(raw: dict, target: np.ndarray, tracklets, length: int, frame_rate: float,
           seeds=(100, 101)) -> tuple[dict, list]:
    """The scene `raw` (with its detector) with its detector's box noise and its walkers' noise, stop rate and desired
    speed set so that the scene shows the sequence's tracklets' motion (`target`, from `tracklet_motion`).
    `tracklets(raw, seed)` runs the scene once: its detections linked as the sequence's were, and its people (each
    frame's scored ids and boxes); each run pools `seeds` and more, up to MAX_SEEDS, until REFINE_WINDOWS windows.

    Two kinds of statistic, matched two ways. How far people walk in a second and how often they stand, the
    sequence's tracklets show as its people do (on the eight shared sequences, the walking windows' median speed
    within 0.80-1.25x of the ground truth's, the standing share within 0.09), but a scene's tracklets do not show
    its own people so (its detector's drift makes people who stand seem to walk): these the scene's people match.
    The jitter and the deviation from constant velocity are the boxes' as much as the people's: these the scene's
    tracklets match, like against like, so that box noise, fragments and the camera count alike on both sides.
    Six runs:
    1. as fitted: the detector's frame-to-frame box noise (NOISE_KEYS) is scaled by the sequence's median jitter over
       the scene's, for a detector fitted on other sequences need not jitter as this one's did (the pooled one jitters
       up to twice as much as the TUD and ADL sequences' own). Its drift is kept: correlated from frame to frame, it
       barely shows in the jitter, and scaled with the noise (as before `calibrate` matched the noise to the jitter)
       it took the scenes' deviation to 1.9 times PETS09-S2L1's and 0.6 times KITTI-17's;
    2. and 3. with that detector, twice: the stop rate is scaled by the odds of the sequence's standing share over
       those of the scene's people's, and the desired speed by the sequence's median walking speed over theirs
       (people who walk the fitted desired speed alone walked slower in the scenes, 0.59-0.80x of the real people on
       seven of the eight shared sequences, before this step). Under a camera going forward the standing share is
       matched by the camera's companions instead (`fit_forward.companions`; added or taken away by the share missing
       times the people's windows a frame): there a person standing on the ground flows out of the picture, and the
       stop rate barely moved the share (ETH-Sunnyday's scene stood 0.15 of its windows at a stop rate of 0.22/s and
       0.13 at 2.8/s), so the walkers keep the stop rate fitted with the flow taken out;
    4. and 5. with that stop rate and speed, and the noise as fitted and a tenth of it: the deviation that the
       detector, SORT and the camera make by themselves (the floor) and how it grows with the walkers' noise. Their
       own deviation adds to the floor in squares; the noise is the one that brings the floor up to the sequence's.
       Where the floor is already above the sequence's (the people are steadier than the boxes show, by how much the
       data cannot say) or the runs show no response, the fourth run's noise is scaled by the sequence's deviation
       over the scene's. Where the sequence's tracklets give fewer than MIN_WINDOWS windows, too few to read their
       deviation (fit_walkers then kept the shipped relaxation and noise), the noise is kept and runs 4 to 6 skipped;
    6. with that noise, the stop rate and speed scaled once more as in 2.: a walker's noise moves how often it seems to
       stand (fast noise slows walkers below STANDING now and then), and without this step PETS09-S2L1's scene stood
       in 0.04 of its windows against the 0.09 it had matched.
    Returns the scene and the runs' keys and measurements (tracklets', then people's)."""
    walk = dict(raw["walk"])
    history: list[tuple[dict, np.ndarray, np.ndarray]] = []
    if not _complete(target):
        return raw, history

    def run(scene: dict, w: dict) -> tuple[np.ndarray, np.ndarray, float]:
        # pooled over seeds, up to REFINE_WINDOWS windows; the tracklets', the people's and their windows a frame
        values, jitter, people = [], [], []
        for seed in range(seeds[0], seeds[0] + MAX_SEEDS):
            rows, truth = tracklets({**scene, "walk": w}, seed)
            frames = frames_of(rows, length)
            values.append(window_values(frames, frame_rate))
            jitter.append(jitters(frames))
            people.append(window_values(truth, frame_rate))
            if seed - seeds[0] + 1 >= len(seeds) and sum(len(v["speed"]) for v in values) >= REFINE_WINDOWS:
                break
        pooled = lambda parts: {k: np.concatenate([v[k] for v in parts]) for k in ("speed", "deviation")}  # noqa: E731
        got = (_measured(pooled(values), np.concatenate(jitter)), _measured(pooled(people), np.zeros(0)))
        history.append((dict(w), *got))
        return (*got, sum(len(v["speed"]) for v in people) / (len(people) * length))  # the people's windows a frame

    def people_matched(scene: dict, w: dict) -> tuple[dict, dict] | None:  # the standing share and walking speed
        first, people, windows = run(scene, w)
        if not _complete(first):
            return None
        factor = {"speed": target[4] / people[4]}
        if scene.get("render", {}).get("camera_forward"):  # who stands in the picture walks with the camera
            scene = _with_companions(scene, (target[2] - people[2]) * windows)
        else:
            factor["stop_rate"] = _odds(target[2]) / _odds(people[2])
        return scene, {**w, **{k: _scaled(max(w[k], 0.01), f, k) for k, f in factor.items() if np.isfinite(f)}}

    jitter = run(raw, walk)[0][3]
    raw = _detector_scaled(raw, target[3] / jitter if jitter > 0 else math.nan)  # boxes that never jitter: kept
    for _ in range(2):  # two steps: the stop rate and the desired speed move each other's statistic
        matched = people_matched(raw, walk)
        if matched is None:
            return {**raw, "walk": walk}, history
        raw, walk = matched
    if target[5] < MIN_WINDOWS:
        return {**raw, "walk": walk}, history
    first = run(raw, walk)[0]
    low = {**walk, "noise": round(max(walk["noise"] / 10, LIMITS["noise"][0]), 4)}
    second = run(raw, low)[0]
    if not _complete(second):
        return {**raw, "walk": walk}, history
    slope = (first[1] ** 2 - second[1] ** 2) / max(walk["noise"] ** 2 - low["noise"] ** 2, 1e-12)
    floor = second[1] ** 2 - slope * low["noise"] ** 2
    if slope > 0 and target[1] ** 2 > floor:
        noise = math.sqrt((target[1] ** 2 - floor) / slope)
    else:  # the floor is at or above the sequence's, or no response was seen: the noise deflated in proportion
        noise = walk["noise"] * target[1] / max(first[1], 1e-6)
    final = {**low, "noise": round(float(np.clip(noise, low["noise"], walk["noise"] * REACH["noise"])), 4)}
    raw, final = people_matched(raw, final) or (raw, final)
    return {**raw, "walk": final}, history


def _with_companions(raw: dict, more: float) -> dict:
    """The scene `raw` with `more` (rounded) people walking with its camera going forward, within the schema's range;
    the key left out where there are none."""
    render, limits = dict(raw["render"]), scn.setting_of("render.camera_companions")[1]
    count = int(np.clip(round(render.pop("camera_companions", 0) + more), limits["lo"], limits["hi"]))
    return {**raw, "render": {**render, **({"camera_companions": count} if count else {})}}


def _complete(measured: np.ndarray) -> bool:
    """Whether `_measured` found the speed, the deviation, the standing share and the jitter (the walking speed it
    need not: nobody may walk a whole second)."""
    return bool(np.all(np.isfinite(measured[:4])))


def _odds(share: float) -> float:
    """The odds of a standing share, a little away from 0 and 1: the two-state walker's stationary standing share is
    stop / (stop + go), so its odds scale with the stop rate."""
    return (share + 0.02) / (1.02 - share)


def _detector_scaled(raw: dict, factor: float) -> dict:
    """The scene `raw` with its detector's box noise (NOISE_KEYS, as its sensor table or preset gives them) times
    `factor`, within NOISE_REACH either way and the schema's range."""
    if not math.isfinite(factor):
        return raw
    factor = float(np.clip(factor, 1 / NOISE_REACH, NOISE_REACH))
    sensor = scn.from_mapping(raw, "fitted scene").sensor
    scaled = {k: round(float(min(getattr(sensor, k) * factor, 1.0)), 4) for k in NOISE_KEYS}
    return {**raw, "sensor": {**raw.get("sensor", {}), **scaled}}


def _scaled(value: float, factor: float, key: str) -> float:
    """`value` times `factor`, the factor within REACH, the result within the schema's LIMITS."""
    factor = float(np.clip(factor, 1 / REACH[key], REACH[key]))
    return round(float(np.clip(value * factor, *LIMITS[key])), 4)


def doors(width: float, height: float, size: float, rows: tuple[float, float], heading: float | None,
          births: float, ahead: bool = False) -> list[dict]:
    """Entry and exit doors at the left and right borders, four along each, spread over `rows` (the band of the
    people's feet, as shares of the height), entries just inside (sharing `births` a frame) and exits just outside
    (`size` px square): walkers, who head for a random exit, cross the scene at the depth where they walk and leave it
    (an exit outside that band would send them into or out of the picture's depth, where the perspective bends a
    straight walk; without exits the world's goal is a point inside it, where they would stay). Where the tracklets
    walk one way (`heading`, degrees, within 45 of across), people enter on the side they come from and leave on the
    other; else on both. Where the camera goes forward (`ahead`), everyone enters through one door over the whole
    band, across the width (people come into view ahead of the camera), and leaves as the ground flows them out."""
    across = None if heading is None else math.cos(math.radians(heading))
    going = ("right",) if across is not None and across > SIDEWAYS else ("left",) if across is not None and \
        across < -SIDEWAYS else ("left", "right")
    coming = [{"left": "right", "right": "left"}[g] for g in going] if len(going) == 1 else going
    side_entries = () if ahead else coming
    out = [{"rect": [0.0, rows[0] * height, width, (rows[1] - rows[0]) * height], "role": "entry",
            "birth_rate": births}] if ahead else []
    for f in (1 / 8, 3 / 8, 5 / 8, 7 / 8):
        y = (rows[0] + f * (rows[1] - rows[0])) * height
        for side in side_entries:
            x = -0.5 * size if side == "left" else width
            out.append({"rect": [x, y - size / 4, 0.5 * size, 0.5 * size], "role": "entry",
                        "birth_rate": births / (4 * len(coming))})
        for side in going:
            out.append({"rect": [-2 * size if side == "left" else width + size, y - size / 2, size, size],
                        "role": "exit"})
    return [{**d, "rect": [round(float(v), 1) for v in d["rect"]],
             **({"birth_rate": round(d["birth_rate"], 4)} if "birth_rate" in d else {})} for d in out]
