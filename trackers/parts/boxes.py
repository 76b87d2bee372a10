"""Box conversions between the detections' x, y, w, h (tlwh), corners x1, y1, x2, y2 and the Kalman states of SORT
(cx, cy, area, aspect) and ByteTrack (cx, cy, aspect, height), each as its reference code computes it."""

from __future__ import annotations

import numpy as np


def corners_to_measurement(corners: np.ndarray) -> np.ndarray:
    """x1, y1, x2, y2 -> SORT's measurement cx, cy, s (area), r (aspect w / h)."""
    w, h = corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1]
    out = np.empty((len(corners), 4))
    out[:, 0], out[:, 1], out[:, 2], out[:, 3] = corners[:, 0] + w / 2, corners[:, 1] + h / 2, w * h, w / h
    return out


def state_to_corners(x: np.ndarray) -> np.ndarray:
    """SORT's state (cx, cy, s, r, ...) -> x1, y1, x2, y2; not a number where s * r < 0 (the reference drops those)."""
    with np.errstate(invalid="ignore"):
        w = np.sqrt(x[:, 2] * x[:, 3])
        h = x[:, 2] / w
    out = np.empty((len(x), 4))
    out[:, 0], out[:, 1], out[:, 2], out[:, 3] = x[:, 0] - w / 2, x[:, 1] - h / 2, x[:, 0] + w / 2, x[:, 1] + h / 2
    return out


def xyah_to_tlwh(m: np.ndarray) -> np.ndarray:
    """Filter means (cx, cy, aspect, height, ...) -> boxes x, y, w, h."""
    out = np.empty((len(m), 4))
    out[:, 2] = m[:, 2] * m[:, 3]
    out[:, 0] = m[:, 0] - out[:, 2] / 2
    out[:, 1] = m[:, 1] - m[:, 3] / 2
    out[:, 3] = m[:, 3]
    return out


def xyah_to_corners(m: np.ndarray) -> np.ndarray:
    """Filter means (cx, cy, aspect, height, ...) -> boxes x1, y1, x2, y2 (as corners(xyah_to_tlwh(m)), in one go)."""
    out = np.empty((len(m), 4))
    width = m[:, 2] * m[:, 3]
    out[:, 0] = m[:, 0] - width / 2
    out[:, 1] = m[:, 1] - m[:, 3] / 2
    out[:, 2] = out[:, 0] + width
    out[:, 3] = out[:, 1] + m[:, 3]
    return out


def tlwh_to_xyah(tlwh: np.ndarray) -> np.ndarray:
    """Boxes x, y, w, h -> the filter's measurement cx, cy, aspect w / h, height."""
    out = np.empty((len(tlwh), 4))
    out[:, :2] = tlwh[:, :2] + tlwh[:, 2:4] / 2
    out[:, 2] = tlwh[:, 2] / tlwh[:, 3]
    out[:, 3] = tlwh[:, 3]
    return out
