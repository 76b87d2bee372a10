"""Drawing ground truth, detections, tracks and a tracker's internals on a frame, with a banner and a legend."""

from __future__ import annotations


import cv2
import numpy as np

from mtt_sim.sim.truth import Truth
from mtt_sim.sim.world import hue_colors

GT_COLOR = (40, 220, 40)
DET_COLOR = (250, 220, 0)
# Track hues leave out the band from orange-yellow to green (0.10 to 0.45 of the hue circle), where the truth's green
# and the detections' yellow lie: a track is never mistaken for either.
_SKIP = (0.10, 0.45)


def track_color(track_id: int) -> tuple[int, ...]:
    """A stable colour per track id: golden-ratio steps around the hue circle, outside the truth's and the
    detections' hues."""
    u = (0.618034 * track_id) % 1.0 * (1.0 - (_SKIP[1] - _SKIP[0]))
    hue = u if u < _SKIP[0] else u + _SKIP[1] - _SKIP[0]
    return tuple(int(c) for c in hue_colors(np.array([hue]))[0])


def _xy(v, scale: float) -> tuple[int, int]:
    return tuple(int(round(c * scale)) for c in v[:2])


def _rect(img, box, color, thickness=1, scale: float = 1.0):
    x, y, w, h = (v * scale for v in box[:4])
    cv2.rectangle(img, (int(round(x)), int(round(y))), (int(round(x + w)) - 1, int(round(y + h)) - 1), color,
                  thickness, cv2.LINE_AA)


def _dashed_rect(img, box, color, scale: float = 1.0, dash: int = 4):
    """A rectangle outline drawn in dashes (detections, so tracks drawn over them stay readable)."""
    x, y, w, h = (int(round(v * scale)) for v in box[:4])
    x1, y1 = x + w - 1, y + h - 1
    for a in range(x, x1 + 1, 2 * dash):
        b = min(a + dash - 1, x1)
        cv2.line(img, (a, y), (b, y), color, 1)
        cv2.line(img, (a, y1), (b, y1), color, 1)
    for a in range(y, y1 + 1, 2 * dash):
        b = min(a + dash - 1, y1)
        cv2.line(img, (x, a), (x, b), color, 1)
        cv2.line(img, (x1, a), (x1, b), color, 1)


def label(img, text: str, corner: tuple[int, int], color, above: bool = True, size: float = 0.4) -> tuple[int, int]:
    """`text` on a filled box of `color` whose lower-left (above=True) or upper-left corner is `corner`, in black or
    white, whichever reads better; returns the box's (width, height)."""
    (w, h), base = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, size, 1)
    x, y = corner
    top = y - h - base - 2 if above else y
    x = int(np.clip(x, 0, max(img.shape[1] - w - 2, 0)))
    top = int(np.clip(top, 0, max(img.shape[0] - h - base - 2, 0)))
    cv2.rectangle(img, (x, top), (x + w + 2, top + h + base + 2), color, -1)
    ink = (0, 0, 0) if 0.299 * color[0] + 0.587 * color[1] + 0.114 * color[2] > 140 else (255, 255, 255)
    cv2.putText(img, text, (x + 1, top + h + 1), cv2.FONT_HERSHEY_SIMPLEX, size, ink, 1, cv2.LINE_AA)
    return w + 2, h + base + 2


def scaled(frame: np.ndarray, scale: int) -> np.ndarray:
    """The frame enlarged `scale` times (nearest neighbour: pixels stay pixels), or a copy at 1."""
    return cv2.resize(frame, None, fx=scale, fy=scale, interpolation=cv2.INTER_NEAREST) if scale != 1 else frame.copy()


def draw_overlay(frame: np.ndarray, truth: Truth, detections: np.ndarray, track_ids: np.ndarray,
                 track_boxes: np.ndarray, trails: dict | None = None, scale: int = 1) -> np.ndarray:
    """The frame, enlarged `scale` times, with truth (green, dark where mostly hidden), detections (dashed yellow)
    and tracks (a colour per id, the id on a label above the box, the trail of its centres)."""
    img = scaled(frame, scale)
    for box, vis in zip(truth.boxes, truth.visibility):
        _rect(img, box, GT_COLOR if vis >= 0.5 else (20, 110, 20), 1 + (scale > 1), scale)
    for det in detections:
        _dashed_rect(img, det, DET_COLOR, scale)
    for tid, box in zip(track_ids.tolist(), track_boxes):
        color = track_color(tid)
        if trails and tid in trails and len(trails[tid]) > 1:
            pts = np.round(np.array(trails[tid]) * scale).astype(np.int32)
            cv2.polylines(img, [pts], False, color, 1 + (scale > 1), cv2.LINE_AA)
        _rect(img, box, color, 2, scale)
        label(img, str(tid), _xy(box, scale), color)
    return img


def draw_debug(img: np.ndarray, primitives: list[dict], scale: int = 1) -> np.ndarray:
    """Draw a tracker's `debug()` primitives on `img` (already enlarged `scale` times) in place and return it.

    Each is a dict with a "kind": "ellipse" (center, axes, angle in degrees), "points" (xy (n, 2), optional
    "weights" drawn as dot size, optional boolean "hidden" drawn as hollow dots), "box" (box x, y, w, h), "text"
    (xy, text: drawn as a tag), "bar" (box x, y, w, h of the track and a "value" in [0, 1], drawn beside the box
    with its number) or "data" (not drawn). An "id" draws it in that track's colour; otherwise an optional RGB
    "color" (white by default)."""
    for p in primitives:
        color = track_color(int(p["id"])) if "id" in p else tuple(int(c) for c in p.get("color", (255, 255, 255)))
        kind = p.get("kind")
        if kind == "ellipse":
            axes = tuple(max(int(round(v * scale)), 1) for v in p["axes"])
            cv2.ellipse(img, _xy(p["center"], scale), axes, float(p.get("angle", 0.0)), 0, 360, color, 1, cv2.LINE_AA)
        elif kind == "points":
            _draw_points(img, p, color, scale)
        elif kind == "box":
            _rect(img, p["box"], color, 1, scale)
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
    """Particles: the heavier, the bigger (radius 1 to 4 px over the cloud's weights); hidden ones hollow."""
    xy = np.round(np.asarray(p["xy"], float).reshape(-1, 2) * scale).astype(int)
    w = np.asarray(p.get("weights", np.ones(len(xy))), float)
    radius = 1 + np.round(3 * w / w.max()).astype(int) if len(w) and w.max() > 0 else np.ones(len(xy), int)
    hidden = np.asarray(p.get("hidden", np.zeros(len(xy), bool)), bool)
    for (x, y), r, h in zip(xy.tolist(), radius.tolist(), hidden.tolist()):
        cv2.circle(img, (x, y), r, color, 1 if h else -1, cv2.LINE_AA)


def _draw_bar(img, box, value: float, color, scale: int) -> None:
    """A vertical bar on the right of `box`, filled to `value` of its height, with the value printed under it."""
    x, y, w, h = (v * scale for v in box[:4])
    x0, y0, y1 = int(round(x + w)) + 2, int(round(y)), int(round(y + h))
    cv2.rectangle(img, (x0, y0), (x0 + 4, y1), (40, 40, 40), -1)
    cv2.rectangle(img, (x0, y1 - int(round((y1 - y0) * np.clip(value, 0, 1)))), (x0 + 4, y1), color, -1)
    label(img, f"{value:.2f}", (x0, y1 + 1), color, above=False, size=0.3)


def draw_banner(img: np.ndarray, text: str) -> np.ndarray:
    """A dark strip across the top of `img` with `text` in white (frame, tracker, running metrics)."""
    (_, h), base = cv2.getTextSize(text, cv2.FONT_HERSHEY_SIMPLEX, 0.4, 1)
    img[: h + base + 6] = (img[: h + base + 6] * 0.3).astype(img.dtype)
    cv2.putText(img, text, (4, h + 3), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (255, 255, 255), 1, cv2.LINE_AA)
    return img


def draw_legend(img: np.ndarray) -> np.ndarray:
    """The key to the colours, bottom left: truth, detection, track."""
    y = img.shape[0] - 3
    x = 3
    for text, color in (("truth", GT_COLOR), ("detection", DET_COLOR), ("track (colour per id)", track_color(1))):
        x += label(img, text, (x, y), color, size=0.35)[0] + 3
    return img


def running_metrics(tp: int, fp: int, fn: int, idsw: int, idf1: float | None) -> str:
    """The banner's metric readout so far."""
    gt = tp + fn
    mota = f"{1 - (fn + fp + idsw) / gt:.3f}" if gt else "-"
    return f"MOTA {mota}  IDF1 {'-' if idf1 is None else f'{idf1:.3f}'}  FP {fp}  FN {fn}  IDSW {idsw}"
