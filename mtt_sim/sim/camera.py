"""The camera: where the image sits over the world, frame by frame, and the warp it makes from one frame to the next.

Two kinds. The first scenarios' cameras (static, pan, follow, shake) cut the image out of the world at a whole-pixel
offset, so nothing is resampled. The warp cameras see the world through an affine pose (world to image coordinates)
that each frame's warp moves on, as a real camera's image moves: `trace` replays a camera-motion file in BoT-SORT's
GMC format, `walking` draws the warps from a model fitted to real walking and driving cameras, `still` from one
fitted to the jitter of cameras on a tripod (`fit`). A frame's warp is the 2x3 affine map of the previous frame's
pixel coordinates onto this frame's, BoT-SORT's convention, in box coordinates (the warp moves a box's corners).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from mtt_sim.sim.config import Scenario
from mtt_sim.sim.world import World

IDENTITY = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
WARP_CAMERAS = ("trace", "walking", "still")
TAIL_CAP = 50.0  # a Student-t draw of the camera models is capped at this many scales


def shift(dx: float, dy: float) -> np.ndarray:
    """The 2x3 warp that moves everything by (dx, dy)."""
    return np.array([[1.0, 0.0, dx], [0.0, 1.0, dy]])


def compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The 2x3 affine map `a` after `b`."""
    return a[:, :2] @ b + np.c_[np.zeros((2, 2)), a[:, 2]]


def invert(a: np.ndarray) -> np.ndarray:
    """The inverse of a 2x3 affine map."""
    inv = np.linalg.inv(a[:, :2])
    return np.c_[inv, -inv @ a[:, 2]]


def warp_boxes(boxes: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Boxes (n, 4) x, y, w, h through the affine map `a`: the bounding box of each box's four warped corners."""
    x0, y0 = boxes[:, 0], boxes[:, 1]
    x1, y1 = x0 + boxes[:, 2], y0 + boxes[:, 3]
    xs = np.stack([x0, x1, x0, x1], 1)
    ys = np.stack([y0, y0, y1, y1], 1)
    u = a[0, 0] * xs + a[0, 1] * ys + a[0, 2]
    v = a[1, 0] * xs + a[1, 1] * ys + a[1, 2]
    lo = np.stack([u.min(1), v.min(1)], 1)
    return np.concatenate([lo, np.stack([u.max(1), v.max(1)], 1) - lo], 1)


class Camera:
    """Where the image window sits in the world: static, panning back and forth, following the targets, or shaking
    by hand. `warp` is the whole-pixel shift it made at its last move (the identity before the first)."""

    def __init__(self, sc: Scenario, rng: np.random.Generator):
        r = sc.render
        self.mode, self.rng = r.camera, rng
        self.image_size = np.array([r.width, r.height], float)
        self.span = np.array(sc.world_size) - self.image_size
        self.velocity = np.array(r.pan_speed, float)
        self.sigma = r.shake
        self.base = self.span / 2 if self.mode not in ("pan", "follow") else np.zeros(2)
        self.jitter = np.zeros(2)
        self.margin = int(math.ceil(4 * self.sigma)) if self.mode == "shake" else 0
        self.warp = IDENTITY

    @property
    def offset(self) -> np.ndarray:
        """World coordinates of the image's top-left pixel (integer: the background is cropped, not resampled)."""
        return np.round(self.base + self.jitter)

    def follow(self, world: World, max_step: np.ndarray | float = np.inf):
        """Move toward centring the targets' mean in the image, at most `max_step` per axis (a following camera
        jumps there at reset)."""
        if len(world.ids):
            boxes = world.boxes()
            wanted = (boxes[:, :2] + boxes[:, 2:] / 2).mean(axis=0) - self.image_size / 2
            self.base = np.clip(self.base + np.clip(wanted - self.base, -max_step, max_step), 0, self.span)

    def advance(self, world: World):
        before = self.offset
        if self.mode == "follow":
            self.follow(world, np.abs(self.velocity))
        elif self.mode == "pan":
            nxt = self.base + self.velocity
            bounce = (nxt < 0) | (nxt > self.span)
            self.velocity = np.where(bounce, -self.velocity, self.velocity)
            self.base = np.clip(nxt, 0, self.span)
        elif self.mode == "shake":  # AR(1): a handheld camera drifts around its rest position
            self.jitter = 0.7 * self.jitter + self.rng.normal(0, self.sigma * math.sqrt(1 - 0.49), 2)
            self.jitter = np.clip(self.jitter, -self.margin, self.margin)
        self.warp = shift(*(before - self.offset))


class WarpCamera:
    """A camera whose image is the world through an affine pose (world to image coordinates), moved on each frame by
    that frame's warp: the poses are the warps composed, from a rest pose that shows the middle of the world. Past the
    last warp the camera holds its last pose. The world's backdrop gets a `margin` so that, as far as one image size
    on each side allows, no pose looks past it."""

    def __init__(self, sc: Scenario, warps: np.ndarray):
        r = sc.render
        self.mode = r.camera
        w, h = r.width, r.height
        base = (np.array(sc.world_size) - (w, h)) / 2
        self.warps = np.asarray(warps, float).copy()
        self.warps[0] = IDENTITY  # frame 0 is the rest pose
        poses = np.empty_like(self.warps)
        poses[0] = shift(*-base)
        for k in range(1, len(poses)):
            poses[k] = compose(self.warps[k], poses[k - 1])
        self.poses = poses
        self.k = 0
        # how far past the world any frame looks: the world points of the image's corners under every pose
        corners = np.array([[0, 0, 1], [w, 0, 1], [0, h, 1], [w, h, 1]], float)
        inverse = np.linalg.inv(poses[:, :, :2])  # world = inv(L) (image - t)
        seen = np.einsum("kij,kcj->kci", inverse, corners[None, :, :2] - poses[:, None, :, 2])
        ww, wh = sc.world_size
        past = max(0.0, -seen[..., 0].min(), -seen[..., 1].min(), seen[..., 0].max() - ww, seen[..., 1].max() - wh)
        self.margin = int(min(math.ceil(past) + 2, max(w, h)))

    @property
    def pose(self) -> np.ndarray:
        """The 2x3 map from world to image coordinates at this frame."""
        return self.poses[min(self.k, len(self.poses) - 1)]

    @property
    def warp(self) -> np.ndarray:
        """This frame's warp: the previous frame's coordinates onto this one's (the identity at frame 0 and past
        the last warp)."""
        return self.warps[self.k] if self.k < len(self.warps) else IDENTITY

    def advance(self, world: World):
        self.k += 1


def model_warps(sc: Scenario, frames: int, rng: np.random.Generator) -> np.ndarray:
    """`frames` warps (the first the identity) of the walking or still camera model, in `sc.render`'s keys."""
    r = sc.render
    if r.camera == "walking":
        scale = (*r.camera_step, math.radians(r.camera_turn), r.camera_zoom / 100)
        corr, tail = (*r.camera_step_corr, r.camera_turn_corr, r.camera_zoom_corr), r.camera_tail
    else:  # still: a camera on a tripod only jitters
        scale, corr, tail = (r.still_jitter, r.still_jitter, 0.0, 0.0), (r.still_jitter_corr,) * 4, r.still_tail
    return draw_warps(scale, corr, tail, r.camera_return, r.width, r.height, frames, rng)


def draw_warps(scale, corr, tail: float, period: float, width: int, height: int, frames: int,
               rng: np.random.Generator) -> np.ndarray:
    """`frames` warps (the first the identity) of a camera whose pose away from rest (its shift across and down, in
    shares of the width; its roll, radians; its log zoom, both about the image centre) moves by a velocity that is
    AR(1) with correlation `corr` and Student-t innovations with `tail` degrees of freedom (heavy tails; a draw capped
    at TAIL_CAP), scaled so that the velocity's spread is `scale` a frame (its standard deviation where the tails are
    Gaussian), and pulled back toward rest by a weak spring of period about 2 pi `period` frames (a quarter of that
    for the roll and the zoom), so that the camera stays over the world. A frame's warp is the pose change."""
    scale = np.array(scale, float) * (width, width, 1, 1)
    corr = np.array(corr, float)
    t = np.clip(rng.standard_t(tail, (frames, 4)), -TAIL_CAP, TAIL_CAP)
    innovations = t * (scale * np.sqrt(1 - corr ** 2))
    pull = np.array([1, 1, 16, 16]) / period ** 2  # roll and zoom come back four times sooner: a camera keeps its
    # horizon and its distance, where a shift carries it along the street
    centre = np.array([width / 2, height / 2])
    state, velocity = np.zeros(4), np.zeros(4)
    states = np.zeros((frames, 4))
    for k in range(1, frames):
        velocity = corr * velocity + innovations[k] - pull * state
        state = state + velocity
        states[k] = state
    dx, dy, roll, zoom = states.T
    s = np.exp(zoom)
    lin = np.empty((frames, 2, 2))
    lin[:, 0, 0] = lin[:, 1, 1] = s * np.cos(roll)
    lin[:, 1, 0] = s * np.sin(roll)
    lin[:, 0, 1] = -lin[:, 1, 0]
    poses = np.concatenate([lin, (centre + np.c_[dx, dy] - lin @ centre)[:, :, None]], axis=2)  # about the centre
    inverse = np.linalg.inv(lin)
    warps = np.empty_like(poses)  # pose k after the inverse of pose k - 1
    warps[1:, :, :2] = lin[1:] @ inverse[:-1]
    warps[1:, :, 2] = poses[1:, :, 2] - np.einsum("kij,kj->ki", warps[1:, :, :2], poses[:-1, :, 2])
    warps[:1] = IDENTITY
    return warps


def make_camera(sc: Scenario, rng: np.random.Generator, trace: np.ndarray | None = None) -> Camera | WarpCamera:
    """The scenario's camera, drawing from `rng`; `trace` holds the warps a `trace` camera replays."""
    mode = sc.render.camera
    if mode == "trace":
        return WarpCamera(sc, trace)
    if mode in WARP_CAMERAS:
        return WarpCamera(sc, model_warps(sc, sc.env.max_steps + 1, rng))
    return Camera(sc, rng)


# ---------------------------------------------------------------- fitting the models to real traces

def components(warps: np.ndarray, width: float, height: float) -> np.ndarray:
    """Per frame after the first: the image centre's shift across and down (shares of the width), the roll (radians)
    and the log of the scale change, of (frames, 2, 3) warps over a `width` x `height` image."""
    w = np.asarray(warps, float)[1:]
    centre = np.array([width / 2, height / 2, 1.0])
    moved = (w @ centre - centre[:2]) / width
    roll = np.arctan2(w[:, 1, 0], w[:, 0, 0])
    zoom = np.log(np.sqrt(np.abs(np.linalg.det(w[:, :, :2]))))
    return np.c_[moved, roll, zoom]


def fit(traces, still: bool = False, period: float = 40.0, frames: int = 20000) -> dict:
    """The walking camera's keys fitted to real traces, each (warps, width, height), or with `still` the still
    camera's. Pooled over the traces: each component's lag-one correlation (the still camera's: one for both axes).
    Then, as the model's velocity is not the data's (the spring of period `period` frames bends it, and the
    innovations' tails thin out in the sum), the rest by simulating the model itself (`frames` frames) and scaling
    its components: the degrees of freedom whose shift a frame has the real 95th percentile over median, nearest;
    the shift's scales across and down in the real proportion of their median sizes, together missing the shift's
    real median and 95th percentile by the same factor; the roll's and the zoom's scales that give their real
    medians."""
    parts = [components(*t) for t in traces]
    joined = np.concatenate(parts)
    rms = np.sqrt(np.mean(joined ** 2, axis=0))
    lagged = np.concatenate([p[1:] * p[:-1] for p in parts])
    corr = np.clip(lagged.mean(axis=0) / np.maximum(rms, 1e-12) ** 2, 0.0, 0.95)
    size = np.median(np.abs(joined), axis=0)  # each component's median size
    if still:  # the same jitter either way
        corr[:] = corr[:2].mean()
        size[:2] = np.median(np.abs(joined[:, :2]))
    moved = np.hypot(joined[:, 0], joined[:, 1])
    want_median, want_p95 = np.median(moved), np.percentile(moved, 95)
    best = None
    for tail in (1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.8, 2.0, 2.5, 3.0, 4.0, 6.0, 10.0, 30.0):
        sim = components(draw_warps((1e-3,) * 4, corr, tail, period, 1000, 1000, frames, np.random.default_rng(0)),
                         1000, 1000)
        gain = size / np.median(np.abs(sim), axis=0)
        shift = np.hypot(sim[:, 0] * gain[0], sim[:, 1] * gain[1])
        median, p95 = np.median(shift), np.percentile(shift, 95)
        miss = abs(math.log(p95 / median / (want_p95 / want_median)))
        if best is None or miss < best[0]:
            gain[:2] *= math.sqrt(want_median * want_p95 / (median * p95))
            best = (miss, tail, 1e-3 * gain)
    _, tail, scale = best
    if still:
        return {"still_jitter": round(float(np.sqrt(scale[0] * scale[1])), 7),
                "still_jitter_corr": round(float(corr[0]), 3), "still_tail": tail}
    return {"camera_step": [round(float(v), 5) for v in scale[:2]],
            "camera_step_corr": [round(float(v), 3) for v in corr[:2]],
            "camera_turn": round(math.degrees(scale[2]), 4), "camera_turn_corr": round(float(corr[2]), 3),
            "camera_zoom": round(float(scale[3]) * 100, 4), "camera_zoom_corr": round(float(corr[3]), 3),
            "camera_tail": tail}


def read_warps(path: str | Path) -> np.ndarray:
    """The (frames, 2, 3) warps of a BoT-SORT GMC file (a line a frame: its 0-based index, then a00 a01 a02 a10 a11
    a12), or a ValueError naming the file and the row."""
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
    except OSError as err:
        raise ValueError(f"camera trace {path}: {err.strerror}") from None
    warps = []
    for row, line in enumerate(lines, 1):
        fields = line.split()
        if not fields:
            continue
        try:
            numbers = [float(f) for f in fields]
        except ValueError:
            raise ValueError(f"camera trace {path}, row {row}: {line.strip()!r} is not numbers") from None
        if len(numbers) != 7 or numbers[0] != len(warps) or not np.isfinite(numbers).all():
            raise ValueError(f"camera trace {path}, row {row}: expected the frame index {len(warps)} and six finite "
                             f"numbers (a00 a01 a02 a10 a11 a12), got {line.strip()!r}")
        warps.append(np.reshape(numbers[1:], (2, 3)))
    if not warps:
        raise ValueError(f"camera trace {path}: no warp in it")
    return np.array(warps)
