"""What the particle filters share: the hand-initialised targets and image size from env.reset's info, the crop
holding many regions, systematic resampling."""

from __future__ import annotations

from typing import Mapping

import numpy as np


def initial_targets(info) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(ids, centres (k, 2), integer sizes (k, 2), at least 4 px) of the boxes env.reset gives hand-initialised trackers,
    checked: `init_ids` (k,) integers and `init_boxes` (k, 4) finite x, y, w, h with w, h > 0."""
    info = info if isinstance(info, Mapping) else {}
    try:
        ids = np.asarray(info.get("init_ids", np.zeros(0, np.int64)))
        boxes = np.asarray(info.get("init_boxes", np.zeros((0, 4))), float)
    except (TypeError, ValueError):
        boxes = ids = np.zeros(1)  # fails the checks below
    if ids.ndim != 1 or ids.dtype.kind not in "iu" or boxes.shape != (len(ids), 4) or not np.isfinite(boxes).all() \
            or (boxes[:, 2:] <= 0).any():
        raise ValueError("a hand-initialised tracker needs env.reset's info: 'init_ids' (k,) integers and 'init_boxes' "
                         "(k, 4) finite boxes x, y, w, h with positive sizes")
    sizes = np.maximum(np.round(boxes[:, 2:]), 4).astype(int)
    return ids.astype(np.int64), boxes[:, :2] + boxes[:, 2:] / 2, sizes


def image_size(info) -> np.ndarray:
    """(W, H) of env.reset's info["image_size"], checked: the box a particle filter's state may lie in."""
    size = np.asarray((info if isinstance(info, Mapping) else {}).get("image_size", ()), float)
    if size.shape != (2,) or not np.isfinite(size).all() or (size <= 0).any():
        raise ValueError("a particle filter needs env.reset's info['image_size']: (width, height), both positive")
    return size


def crop_around(frame: np.ndarray, centres: np.ndarray, size) -> tuple[np.ndarray, np.ndarray]:
    """(origin, crop): the part of the frame holding every w x h region centred at `centres` (n, 2), with a
    2-pixel margin for gradients; features of the whole frame would cost far more than those of these pixels."""
    half = np.asarray(size) / 2 + 2
    h, w = frame.shape[:2]
    x0, y0 = np.clip(np.floor(centres.min(axis=0) - half).astype(int), 0, (w - 1, h - 1))
    x1, y1 = np.clip(np.ceil(centres.max(axis=0) + half).astype(int) + 1, (x0 + 1, y0 + 1), (w, h))
    return np.array([x0, y0], float), np.ascontiguousarray(frame[y0:y1, x0:x1])


def systematic_resample(weights: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Indices of a systematic resample of each row of `weights` (targets, particles), rows summing to one."""
    k, n = weights.shape
    positions = (rng.random((k, 1)) + np.arange(n)[None]) / n
    cumulative = np.cumsum(weights, axis=1)
    cumulative[:, -1] = 1.0
    return np.stack([np.searchsorted(c, p) for c, p in zip(cumulative, positions)])
