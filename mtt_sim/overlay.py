"""Drawing ground truth, detections and tracks on a frame, and writing videos."""

from __future__ import annotations

import cv2
import numpy as np

from .truth import Truth
from .world import hue_colors

GT_COLOR = (40, 220, 40)
DET_COLOR = (250, 220, 0)


def _rect(img, box, color, thickness=1):
    x, y, w, h = (int(round(v)) for v in box[:4])
    cv2.rectangle(img, (x, y), (x + w - 1, y + h - 1), color, thickness, cv2.LINE_AA)


def _dashed_rect(img, box, color, dash: int = 4):
    """A rectangle outline drawn in dashes (detections, so tracks drawn over them stay readable)."""
    x, y, w, h = (int(round(v)) for v in box[:4])
    x1, y1 = x + w - 1, y + h - 1
    for a in range(x, x1 + 1, 2 * dash):
        b = min(a + dash - 1, x1)
        cv2.line(img, (a, y), (b, y), color, 1)
        cv2.line(img, (a, y1), (b, y1), color, 1)
    for a in range(y, y1 + 1, 2 * dash):
        b = min(a + dash - 1, y1)
        cv2.line(img, (x, a), (x, b), color, 1)
        cv2.line(img, (x1, a), (x1, b), color, 1)


def track_color(track_id: int) -> tuple[int, ...]:
    """A stable, well-separated colour per track id."""
    return tuple(int(c) for c in hue_colors(np.array([0.618034 * track_id]))[0])


def draw_overlay(frame: np.ndarray, truth: Truth, detections: np.ndarray, track_ids: np.ndarray,
                 track_boxes: np.ndarray, trails: dict | None = None) -> np.ndarray:
    """A copy of `frame` with truth (thin green, dark where mostly hidden), detections (dashed yellow) and tracks
    (per-id colour, id label, short trail of centres)."""
    img = frame.copy()
    for box, vis in zip(truth.boxes, truth.visibility):
        _rect(img, box, GT_COLOR if vis >= 0.5 else (20, 110, 20))
    for det in detections:
        _dashed_rect(img, det, DET_COLOR)
    for tid, box in zip(track_ids.tolist(), track_boxes):
        color = track_color(tid)
        _rect(img, box, color, 2)
        cv2.putText(img, str(tid), (int(box[0]), max(int(box[1]) - 3, 8)), cv2.FONT_HERSHEY_SIMPLEX, 0.4, color, 1, cv2.LINE_AA)
        if trails and tid in trails and len(trails[tid]) > 1:
            pts = np.round(np.array(trails[tid])).astype(np.int32)
            cv2.polylines(img, [pts], False, color, 1, cv2.LINE_AA)
    return img


def draw_debug(img: np.ndarray, primitives: list[dict]) -> np.ndarray:
    """Draw a tracker's `debug()` primitives on `img` in place and return it. Each is a dict with "kind":
    "ellipse" (center, axes, angle in degrees), "points" (xy (n, 2)), "box" (box x, y, w, h), "text" (xy, text)
    or "data" (not drawn); optional "color" (RGB)."""
    for p in primitives:
        color = tuple(int(c) for c in p.get("color", (255, 255, 255)))
        kind = p.get("kind")
        if kind == "ellipse":
            center = tuple(int(round(v)) for v in p["center"])
            axes = tuple(max(int(round(v)), 1) for v in p["axes"])
            cv2.ellipse(img, center, axes, float(p.get("angle", 0.0)), 0, 360, color, 1, cv2.LINE_AA)
        elif kind == "points":
            for x, y in np.round(np.asarray(p["xy"], float).reshape(-1, 2)).astype(int).tolist():
                cv2.circle(img, (x, y), 1, color, -1)
        elif kind == "box":
            _rect(img, p["box"], color)
        elif kind == "data":  # values for inspection (a validation matrix, probabilities), nothing to draw
            continue
        elif kind == "text":
            x, y = (int(round(v)) for v in p["xy"])
            cv2.putText(img, str(p["text"]), (x, y), cv2.FONT_HERSHEY_SIMPLEX, 0.35, color, 1, cv2.LINE_AA)
        else:
            raise ValueError(f"debug primitive kind {kind!r}: allowed: 'ellipse', 'points', 'box', 'text', 'data'")
    return img


class VideoWriter:
    """MP4 (mp4v) or AVI (MJPG) writer taking RGB frames; the codec follows the file extension."""

    def __init__(self, path: str, size: tuple[int, int], fps: float = 25.0):
        fourcc = cv2.VideoWriter_fourcc(*("MJPG" if str(path).lower().endswith(".avi") else "mp4v"))
        self._writer = cv2.VideoWriter(str(path), fourcc, fps, size)
        if not self._writer.isOpened():
            raise OSError(f"cannot open video file {path} for writing (use .mp4 or .avi)")

    def write(self, rgb: np.ndarray):
        self._writer.write(cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))

    def close(self):
        self._writer.release()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
