"""The renderer: one video frame and its per-pixel label map, drawn in the same pass with OpenCV.

Targets and occluders are drawn in depth order (standing: by the y of their base; topdown: by
layer, occluders on top) into an RGB frame and a uint16 label map whose value is the target's
slot + 1 where that target is visible, 0 elsewhere. Coordinates use OpenCV's fixed-point
``shift`` so blobs move smoothly by sub-pixel amounts.
"""

from __future__ import annotations

import math
from functools import cached_property

import cv2
import numpy as np

from mtt_sim.sim.camera import WarpCamera, compose, invert, make_camera, shift, warp_boxes
from mtt_sim.sim.config import TEXTURES, Scenario
from mtt_sim.sim.world import World

SHIFT = 4
_ONE = 1 << SHIFT


def fixed_point(boxes: np.ndarray) -> tuple[list, list, list, list]:
    """OpenCV fixed-point geometry of boxes (n, 4): ellipse centres and axes, rectangle corners, as int lists."""
    fp = boxes * _ONE
    half = fp[:, 2:] / 2
    centre = np.rint(fp[:, :2] + half - _ONE / 2).astype(int).tolist()
    axes = np.maximum(np.rint(half), 1).astype(int).tolist()
    p1 = np.rint(fp[:, :2]).astype(int).tolist()
    p2 = np.rint(fp[:, :2] + fp[:, 2:] - _ONE).astype(int).tolist()
    return centre, axes, p1, p2


def draw_fixed(img: np.ndarray, geometry, i: int, is_rect: bool, value) -> None:
    """Fill shape i of `fixed_point` geometry on `img`."""
    centre, axes, p1, p2 = geometry
    if is_rect:
        cv2.rectangle(img, p1[i], p2[i], value, -1, cv2.LINE_8, SHIFT)
    else:
        cv2.ellipse(img, centre[i], axes[i], 0, 0, 360, value, -1, cv2.LINE_8, SHIFT)


def draw_blob(img: np.ndarray, box, is_rect: bool, value) -> None:
    """Fill one box's ellipse (or rectangle) on `img`; box is x, y, w, h in `img` pixels."""
    x, y, w, h = (float(v) * _ONE for v in box)
    geometry = ([(round(x + w / 2 - _ONE / 2), round(y + h / 2 - _ONE / 2))], [(max(round(w / 2), 1), max(round(h / 2), 1))],
                [(round(x), round(y))], [(round(x + w - _ONE), round(y + h - _ONE))])
    draw_fixed(img, geometry, 0, is_rect, value)


class Renderer:
    """Draws frames and label maps of a World seen through a Camera (or a WarpCamera: `trace` holds the warps a
    trace camera replays)."""

    def __init__(self, sc: Scenario, rng: np.random.Generator, trace: np.ndarray | None = None):
        self.sc, self.rng = sc, rng
        r = sc.render
        self.shape = (r.height, r.width)
        self.camera = make_camera(sc, np.random.default_rng(rng.integers(2**63)), trace)
        self.warped = isinstance(self.camera, WarpCamera)
        self.reference: tuple[np.ndarray, np.ndarray] | None = None  # a warped frame's boxes before the warp, and it
        self.photometric_seed = int(rng.integers(2**63))
        occ = sc.occluders
        self.occluder_boxes = np.array([o.rect for o in occ], float).reshape(-1, 4)
        self.occluder_depth = (self.occluder_boxes[:, 1] + self.occluder_boxes[:, 3]) if sc.world.projection == "standing" \
            else np.full(len(occ), np.inf)
        self.occluder_is_rect = np.array([o.shape == "rect" for o in occ], bool)

    @cached_property
    def _looks(self) -> tuple[np.ndarray, list, np.ndarray]:
        """(background canvas, pixel-noise bank, texture tile), drawn from the renderer's generator, in this order,
        the first time a frame is drawn. Nothing else draws from it after the constructor, so they are the same
        whenever they are made, and an episode without frames (label maps only) never pays for them: at 960x540
        they are most of a reset."""
        r = self.sc.render
        canvas = self._background()
        bank = [_signed_parts(_normal(self.rng, r.noise, self.shape + (3,))) for _ in range(4)] if r.noise > 0 else []
        return canvas, bank, self.rng.uniform(-45, 45, (32, 32))

    @property
    def canvas(self) -> np.ndarray:
        """The static world backdrop the frames are cut from."""
        return self._looks[0]

    def _background(self) -> np.ndarray:
        """The static world backdrop, with a margin for a shaking or warping camera."""
        r = self.sc.render
        m = self.camera.margin
        w, h = (int(math.ceil(v)) + 2 * m for v in self.sc.world_size)
        img = np.empty((h, w, 3), np.uint8)
        img[:] = r.background_color
        if r.background in ("noise", "clutter"):
            low = cv2.resize(_normal(self.rng, 14, (h // 8 + 1, w // 8 + 1, 3)), (w, h), interpolation=cv2.INTER_CUBIC)
            fine = _normal(self.rng, 5, (h, w, 3))
            img = np.clip(img + low + fine, 0, 255).astype(np.uint8)
        if r.background == "clutter":
            colors = np.array([g.color for g in self.sc.groups], float)
            sizes = np.array([g.size for g in self.sc.groups], float)
            for _ in range(r.background_blobs):
                k = self.rng.integers(len(colors))
                bw, bh = sizes[k] * self.rng.uniform(0.5, 1.5, 2)
                x, y = self.rng.uniform(0, w), self.rng.uniform(0, h)
                color = np.clip(colors[k] + self.rng.normal(0, 25, 3), 0, 255)
                draw_blob(img, (x - bw / 2, y - bh / 2, bw, bh), bool(self.rng.random() < 0.3), color.tolist())
        return img

    def image_boxes(self, world: World) -> np.ndarray:
        """Every target's drawn box in image pixels (a warping camera's: the bounding box of its warped corners)."""
        boxes = world.boxes()
        if self.warped:
            return warp_boxes(boxes, self.camera.pose)
        boxes[:, :2] -= self.camera.offset
        return boxes

    def occluder_image_boxes(self) -> np.ndarray:
        """Every occluder's box in image pixels."""
        if self.warped:
            return warp_boxes(self.occluder_boxes, self.camera.pose)
        return self.occluder_boxes - np.append(self.camera.offset, (0, 0))

    def render(self, world: World, draw_frame: bool = True, show_targets: bool = True):
        """(frame or None, labels, image boxes) for the world's current state."""
        if self.warped:
            return self._render_warped(world, draw_frame, show_targets)
        h, w = self.shape
        off = self.camera.offset.astype(int)
        m = self.camera.margin
        labels = np.zeros(self.shape, np.uint16)
        frame = self.canvas[off[1] + m: off[1] + m + h, off[0] + m: off[0] + m + w].copy() if draw_frame else None
        boxes = self.image_boxes(world)
        n = len(boxes) if show_targets else 0
        self._draw(world, frame, labels, boxes[:n], self.occluder_image_boxes())
        if frame is not None:
            frame = self._photometric(frame, world.t)
        return frame, labels, boxes

    def _render_warped(self, world: World, draw_frame: bool, show_targets: bool):
        """Draw the part of the world the image sees, as the static path does (a crop of the backdrop, the targets and
        occluders on it), then warp it into the image by the camera's pose: the frame bilinearly, the label map by
        nearest neighbour; what lies past the backdrop is the background colour."""
        h, w = self.shape
        pose = self.camera.pose
        m = self.camera.margin
        ww, wh = (int(math.ceil(v)) for v in self.sc.world_size)
        corners = np.array([[0, 0], [w, 0], [0, h], [w, h]], float)
        back = invert(pose)
        seen = corners @ back[:, :2].T + back[:, 2]
        x0, y0 = np.clip(np.floor(seen.min(axis=0)).astype(int) - 1, -m, (ww + m, wh + m))
        x1, y1 = np.clip(np.ceil(seen.max(axis=0)).astype(int) + 2, -m, (ww + m, wh + m))
        world_boxes = world.boxes()
        if x1 <= x0 or y1 <= y0:  # the image sees nothing of the world
            x0, y0, x1, y1 = -m, -m, 1 - m, 1 - m  # a pixel of it, warped out of sight
        labels = np.zeros((y1 - y0, x1 - x0), np.uint16)
        frame = self.canvas[y0 + m: y1 + m, x0 + m: x1 + m].copy() if draw_frame else None
        n = len(world_boxes) if show_targets else 0
        local = world_boxes - (x0, y0, 0, 0)
        self._draw(world, frame, labels, local[:n], self.occluder_boxes - (x0, y0, 0, 0))
        crop_to_image = compose(pose, shift(x0, y0))  # in box coordinates; in pixel indices a centre is at +0.5:
        lin = crop_to_image[:, :2]
        to_image = np.c_[lin, crop_to_image[:, 2] + (lin - np.eye(2)) @ (0.5, 0.5)]
        self.reference = (local, to_image)
        labels = cv2.warpAffine(labels, to_image, (w, h), flags=cv2.INTER_NEAREST, borderMode=cv2.BORDER_CONSTANT,
                                borderValue=0)
        if frame is not None:  # through four channels: the same pixels, in half the time of three
            frame = cv2.warpAffine(cv2.cvtColor(frame, cv2.COLOR_RGB2RGBA), to_image, (w, h), flags=cv2.INTER_LINEAR,
                                   borderMode=cv2.BORDER_CONSTANT,
                                   borderValue=(*(int(c) for c in self.sc.render.background_color), 0))
            frame = self._photometric(cv2.cvtColor(frame, cv2.COLOR_RGBA2RGB), world.t)
        return frame, labels, warp_boxes(world_boxes, pose)

    def _draw(self, world: World, frame: np.ndarray | None, labels: np.ndarray, boxes: np.ndarray,
              occluder_boxes: np.ndarray) -> None:
        """Draw the targets' `boxes` (the first len(boxes) slots) and the occluders in depth order into the label map
        and the frame, both in the same pixel coordinates."""
        h, w = labels.shape
        n = len(boxes)
        all_boxes = np.concatenate([boxes, occluder_boxes])
        onscreen = (all_boxes[:, 0] < w) & (all_boxes[:, 1] < h) & (all_boxes[:, 0] + all_boxes[:, 2] > 0) & \
                   (all_boxes[:, 1] + all_boxes[:, 3] > 0)
        order = np.argsort(np.concatenate([world.depth()[:n], self.occluder_depth]), kind="stable")
        is_rect = world.shape_is_rect[world.group]
        texture = world.texture_of_group[world.group]
        colors = world.color.tolist()
        geometry = fixed_point(all_boxes)
        rect = np.concatenate([is_rect[:n], self.occluder_is_rect]).tolist()
        for i in order[onscreen[order]].tolist():
            if i < n:
                draw_fixed(labels, geometry, i, rect[i], i + 1)
                if frame is not None:
                    draw_fixed(frame, geometry, i, rect[i], colors[i])
                    if texture[i]:
                        self._texture(frame, labels, i, all_boxes[i], texture[i], colors[i])
            else:
                draw_fixed(labels, geometry, i, rect[i], 0)
                if frame is not None:
                    draw_fixed(frame, geometry, i, rect[i], self.sc.occluders[i - n].color)

    def _texture(self, frame, labels, i, box, kind, color):
        """Paint stripes, checks or noise on target i's visible pixels, fixed to the target so it moves with it."""
        h, w = labels.shape
        x0, y0 = max(int(box[0]), 0), max(int(box[1]), 0)
        x1, y1 = min(int(box[0] + box[2]) + 1, w), min(int(box[1] + box[3]) + 1, h)
        if x1 <= x0 or y1 <= y0:
            return
        mine = labels[y0:y1, x0:x1] == i + 1
        u = (np.arange(x0, x1) - box[0]) / max(box[2], 1)
        v = (np.arange(y0, y1) - box[1]) / max(box[3], 1)
        name = TEXTURES[kind]
        if name == "noise":  # the tile's 32 x 32 colours, then looked up per pixel
            shades = np.clip(np.asarray(color) + self._looks[2][..., None], 0, 255).astype(np.uint8)
            paint = shades[(v * 32).astype(int) % 32][:, (u * 32).astype(int) % 32]
        else:
            bands_v = (np.floor(v * 6) % 2).astype(bool)
            pattern = bands_v[:, None] if name == "stripes" else bands_v[:, None] ^ (np.floor(u * 4) % 2).astype(bool)[None]
            mine &= pattern
            paint = np.empty((y1 - y0, x1 - x0, 3), np.uint8)
            paint[:] = (0.5 * np.asarray(color)).astype(np.uint8)
        cv2.copyTo(paint, mine.view(np.uint8), frame[y0:y1, x0:x1])  # in place, far faster than a boolean index

    def _photometric(self, frame: np.ndarray, t: int) -> np.ndarray:
        """Blur, global illumination (brightness, drift, flicker) and pixel noise.

        Their randomness is keyed on the frame index, so drawing a frame or not never shifts other random streams.
        """
        r = self.sc.render
        bank = self._looks[1]
        rng = np.random.default_rng((self.photometric_seed, t)) if r.flicker > 0 or bank else None
        if r.blur > 0:
            frame = cv2.GaussianBlur(frame, (0, 0), r.blur)
        gain = r.brightness * (1 + r.illumination_drift * math.sin(2 * math.pi * t / r.illumination_period))
        if r.flicker > 0:
            gain *= 1 + r.flicker * rng.normal()
        if gain != 1.0:
            frame = cv2.convertScaleAbs(frame, alpha=gain)
        if bank:
            up, down = bank[rng.integers(len(bank))]
            frame = cv2.subtract(cv2.add(frame, up), down)
        return frame


def _normal(rng: np.random.Generator, sigma: float, shape: tuple) -> np.ndarray:
    """rng.normal(0, sigma, shape), the same values from the same stream, in a third of the time (a large array at
    every reset)."""
    out = rng.standard_normal(shape)
    out *= sigma
    return out


def _signed_parts(noise: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Noise rounded to integers as two uint8 images, its positive and its negative part: adding one and subtracting
    the other, each saturating, gives the frame plus the noise clipped to 0..255, five times faster than one
    mixed-type add."""
    whole = np.clip(np.rint(noise, out=noise), -255, 255, out=noise).astype(np.int16)
    return np.maximum(whole, 0).astype(np.uint8), np.maximum(-whole, 0).astype(np.uint8)
