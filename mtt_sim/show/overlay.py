"""Drawing ground truth, detections, tracks and a tracker's internals on a frame, with a banner and a legend."""

from __future__ import annotations


import cv2
import numpy as np

from mtt_sim.core.frame import Truth

# The truth is magenta, the detections cyan: far from every fixed colour a shipped scene paints (its backgrounds are
# grey, brown, green or near white, its occluders grey, brown or yellow, its uniform targets red, dark or white; only
# targets of random hue come near). The tracks take bright colours far from both, in an order where neighbouring ids
# differ most; tests/test_overlay.py checks the distances, to the scenes' own colours too.
GT_COLOR = (255, 0, 255)
GT_HIDDEN_COLOR = (150, 0, 150)  # a target mostly hidden
DET_COLOR = (0, 255, 255)
TRACK_PALETTE = ((0, 149, 255), (191, 255, 102), (255, 64, 0), (40, 80, 255), (255, 212, 0), (0, 230, 0),
                 (255, 166, 102))  # azure, lime, red-orange, blue, yellow, green, peach

# Sizes read well at the reference frame's shorter side (crossing's 288 px) and grow with it; never below them.
REFERENCE_SIDE = 288


def unit(img: np.ndarray) -> float:
    """How many times the reference sizes `img` draws with: its shorter side over 288 px, at least 1 (smaller frames
    keep legible text)."""
    return max(1.0, min(img.shape[:2]) / REFERENCE_SIDE)


def _px(u: float, base: float) -> int:
    """A line width or radius of `base` px at the reference size, grown by `u`, at least 1 px."""
    return max(1, int(base * u + 0.5))


def _ink(u: float) -> int:
    """The text stroke: 1 px up to 2.5 times the reference size, then thicker."""
    return max(1, int(u * 0.6 + 0.5))


def track_color(track_id: int) -> tuple[int, ...]:
    """A stable colour per track id from `TRACK_PALETTE` (id 1 takes the first; it repeats every seven ids)."""
    return TRACK_PALETTE[(int(track_id) - 1) % len(TRACK_PALETTE)]


def _xy(v, scale: float) -> tuple[int, int]:
    return tuple(int(round(c * scale)) for c in v[:2])


def _rect(img, box, color, thickness=1, scale: float = 1.0):
    """A box's outline on whole pixels, in exactly `color` (anti-aliasing an upright box only blurs it, and blends its
    colour with an outline under it)."""
    x, y, w, h = (v * scale for v in box[:4])
    cv2.rectangle(img, (int(round(x)), int(round(y))), (int(round(x + w)) - 1, int(round(y + h)) - 1), color,
                  thickness, cv2.LINE_8)


def _dashed_rect(img, box, color, scale: float = 1.0, dash: int = 4, thickness: int = 1):
    """A rectangle outline drawn in dashes (detections, so tracks drawn over them stay readable)."""
    x, y, w, h = (int(round(v * scale)) for v in box[:4])
    x1, y1 = x + w - 1, y + h - 1
    for a in range(x, x1 + 1, 2 * dash):
        b = min(a + dash - 1, x1)
        cv2.line(img, (a, y), (b, y), color, thickness)
        cv2.line(img, (a, y1), (b, y1), color, thickness)
    for a in range(y, y1 + 1, 2 * dash):
        b = min(a + dash - 1, y1)
        cv2.line(img, (x, a), (x, b), color, thickness)
        cv2.line(img, (x1, a), (x1, b), color, thickness)


def label(img, text: str, corner: tuple[int, int], color, above: bool = True, size: float = 0.4) -> tuple[int, int]:
    """`text` on a filled box of `color` whose lower-left (above=True) or upper-left corner is `corner`, in black or
    white, whichever reads better; returns the box's (width, height). `size` is the font scale at the reference
    frame size, grown with `img` (see `unit`)."""
    u = unit(img)
    size, ink, pad = size * u, _ink(u), _px(u, 1)
    (w, h), base = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, size, ink)
    x, y = corner
    top = y - h - base - 2 * pad if above else y
    x = int(np.clip(x, 0, max(img.shape[1] - w - 2 * pad, 0)))
    top = int(np.clip(top, 0, max(img.shape[0] - h - base - 2 * pad, 0)))
    cv2.rectangle(img, (x, top), (x + w + 2 * pad, top + h + base + 2 * pad), color, -1)
    fg = (0, 0, 0) if 0.299 * color[0] + 0.587 * color[1] + 0.114 * color[2] > 140 else (255, 255, 255)
    cv2.putText(img, text, (x + pad, top + h + pad), cv2.FONT_HERSHEY_SIMPLEX, size, fg, ink, cv2.LINE_AA)
    return w + 2 * pad, h + base + 2 * pad


def scaled(frame: np.ndarray, scale: int) -> np.ndarray:
    """The frame enlarged `scale` times (nearest neighbour: pixels stay pixels), or a copy at 1."""
    return cv2.resize(frame, None, fx=scale, fy=scale, interpolation=cv2.INTER_NEAREST) if scale != 1 else frame.copy()


def _fit(thickness: int, box, scale: float) -> int:
    """A box's outline no thicker than an eighth of its narrower side (small targets stay visible inside it)."""
    return max(1, min(thickness, int(min(box[2], box[3]) * scale / 8)))


def draw_overlay(frame: np.ndarray, truth: Truth, detections: np.ndarray, track_ids: np.ndarray,
                 track_boxes: np.ndarray, trails: dict | None = None, scale: int = 1) -> np.ndarray:
    """The frame, enlarged `scale` times, with truth (magenta, dark where mostly hidden), detections (dashed cyan)
    and tracks (a colour per id, the id on a label above the box, the trail of its centres); line widths and text
    grow with the picture (see `unit`), and a small box keeps a thin outline and a small tag."""
    img = scaled(frame, scale)
    u = unit(img)
    thin, thick, dash = _px(u, 1), _px(u, 1.5), _px(u, 4)
    for box, vis in zip(truth.boxes, truth.visibility):
        _rect(img, box, GT_COLOR if vis >= 0.5 else GT_HIDDEN_COLOR, _fit(thin, box, scale), scale)
    for det in detections:
        _dashed_rect(img, det, DET_COLOR, scale, dash, _fit(thin, det, scale))
    for tid, box in zip(track_ids.tolist(), track_boxes):
        color = track_color(tid)
        if trails and tid in trails and len(trails[tid]) > 1:
            pts = np.round(np.array(trails[tid]) * scale).astype(np.int32)
            cv2.polylines(img, [pts], False, color, thin, cv2.LINE_AA)
        _rect(img, box, color, _fit(thick, box, scale), scale)
        tag = min(0.35, max(0.4, box[3] * scale / 40) / u)  # a small box, a smaller tag (never below 0.4)
        label(img, str(tid), _xy(box, scale), color, size=tag)
    return img


def draw_debug(img: np.ndarray, primitives: list[dict], scale: int = 1) -> np.ndarray:
    """Draw a tracker's `debug()` primitives on `img` (already enlarged `scale` times) in place and return it.

    Each is a dict with a "kind": "ellipse" (center, axes, angle in degrees), "points" (xy (n, 2), optional
    "weights" drawn as dot size, optional boolean "hidden" drawn as hollow dots), "box" (box x, y, w, h), "text"
    (xy, text: drawn as a tag), "bar" (box x, y, w, h of the track and a "value" in [0, 1], drawn beside the box
    with its number) or "data" (not drawn). An "id" draws it in that track's colour; otherwise an optional RGB
    "color" (white by default). Line widths, dots and text grow with the picture (see `unit`)."""
    thin = _px(unit(img), 1)
    for p in primitives:
        color = track_color(int(p["id"])) if "id" in p else tuple(int(c) for c in p.get("color", (255, 255, 255)))
        kind = p.get("kind")
        if kind == "ellipse":
            axes = tuple(max(int(round(v * scale)), 1) for v in p["axes"])
            cv2.ellipse(img, _xy(p["center"], scale), axes, float(p.get("angle", 0.0)), 0, 360, color, thin,
                        cv2.LINE_AA)
        elif kind == "points":
            _draw_points(img, p, color, scale)
        elif kind == "box":
            _rect(img, p["box"], color, thin, scale)
        elif kind == "text":
            label(img, str(p["text"]), _xy(p["xy"], scale), color, above=False, size=0.35)
        elif kind == "bar":
            _draw_bar(img, p["box"], float(p["value"]), color, scale)
        elif kind == "data":  # values for inspection (a validation matrix, probabilities), nothing to draw
            continue
        else:
            raise ValueError(f"debug primitive kind {kind!r}: allowed: 'ellipse', 'points', 'box', 'text', 'bar', "
                             "'data'")
    return img


def _draw_points(img, p: dict, color, scale: int) -> None:
    """Particles: the heavier, the bigger (radius 1 to 3 px at the reference size, over the cloud's weights); hidden
    ones hollow."""
    u = unit(img)
    xy = np.round(np.asarray(p["xy"], float).reshape(-1, 2) * scale).astype(int)
    w = np.asarray(p.get("weights", np.ones(len(xy))), float)
    radius = 1 + 2 * w / w.max() if len(w) and w.max() > 0 else np.ones(len(xy))
    radius = np.maximum(np.round(radius * u), 1).astype(int)
    hidden = np.asarray(p.get("hidden", np.zeros(len(xy), bool)), bool)
    for (x, y), r, h in zip(xy.tolist(), radius.tolist(), hidden.tolist()):
        cv2.circle(img, (x, y), r, color, _px(u, 1) if h else -1, cv2.LINE_AA)


def _draw_bar(img, box, value: float, color, scale: int) -> None:
    """A vertical bar on the right of `box`, filled to `value` of its height, with the value printed under it."""
    u = unit(img)
    x, y, w, h = (v * scale for v in box[:4])
    x0, y0, y1 = int(round(x + w)) + _px(u, 2), int(round(y)), int(round(y + h))
    x1 = x0 + _px(u, 2.5)
    cv2.rectangle(img, (x0, y0), (x1, y1), (40, 40, 40), -1)
    cv2.rectangle(img, (x0, y1 - int(round((y1 - y0) * np.clip(value, 0, 1)))), (x1, y1), color, -1)
    label(img, f"{value:.2f}", (x0, y1 + 1), color, above=False, size=0.3)


def banner_size(img: np.ndarray, text: str) -> float:
    """The banner's font scale: 0.4 at the reference frame size, grown with `img` (see `unit`), shrunk to fit its
    width if it must (never below 0.3)."""
    size = 0.4 * unit(img)
    width = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, size, _ink(unit(img)))[0][0]
    room = img.shape[1] - 2 * _px(unit(img), 4)
    return max(0.3, size * min(1.0, room / max(width, 1)))


def draw_banner(img: np.ndarray, text: str) -> np.ndarray:
    """A dark strip across the top of `img` with `text` in white (frame, tracker, running metrics)."""
    u = unit(img)
    size, ink, pad = banner_size(img, text), _ink(u), _px(u, 3)
    (_, h), base = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, size, ink)
    img[: h + base + 2 * pad] = (img[: h + base + 2 * pad] * 0.3).astype(img.dtype)
    cv2.putText(img, text, (_px(u, 4), h + pad), cv2.FONT_HERSHEY_SIMPLEX, size, (255, 255, 255), ink, cv2.LINE_AA)
    return img


def draw_legend(img: np.ndarray) -> np.ndarray:
    """The key to the colours, bottom left: truth, detection, track."""
    gap = _px(unit(img), 3)
    y = img.shape[0] - gap
    x = gap
    for text, color in (("truth", GT_COLOR), ("detection", DET_COLOR), ("track (colour per id)", track_color(1))):
        x += label(img, text, (x, y), color, size=0.35)[0] + gap
    return img


def running_metrics(tp: int, fp: int, fn: int, idsw: int, idf1: float | None) -> str:
    """The banner's metric readout so far."""
    gt = tp + fn
    mota = f"{1 - (fn + fp + idsw) / gt:.3f}" if gt else "-"
    return f"MOTA {mota}  IDF1 {'-' if idf1 is None else f'{idf1:.3f}'}  FP {fp}  FN {fn}  IDSW {idsw}"
