"""The boxes' per-frame noise matched to how much the detections themselves jump from frame to frame.

`calibrate` first reads the per-frame box noise off the detections' residuals about the ground truth. Annotated boxes
jitter too, and that jitter lands in the residuals, so the twin (the ground truth plus the fitted noise) counts it
twice: on the eight shared MOT15 sequences its boxes jumped 1.7 times as much as the real detections (docs/
real_data.md). Here the noise is set so that the twin's jitter is the data's: the jitter of the twin with no per-frame
noise (the annotation's and the drift's) is measured, and the noise fills the rest, adding in quadrature, with one
correction step for what the medians do not add.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

KEYS = ("box_noise", "box_size_noise")  # the per-frame noise of the centre and of the size, matched to these:
NAMES = ("box jitter, centre x", "box jitter, height")


def jitter(hit: np.ndarray, box: np.ndarray, cont: np.ndarray) -> tuple[float, float]:
    """How much a person's true detections jump from frame to frame: the median |second difference| of their centre
    x and of their height over three frames in a row, over the height. Rows are person-frames in chain order (`cont`:
    the row continues the previous one's person in the next frame); `hit` marks a true detection, `box` its box."""
    three = hit[:-2] & hit[1:-1] & hit[2:] & cont[1:-1] & cont[2:]  # rows i, i+1, i+2: one person, frames in a row
    if not three.any():
        return math.nan, math.nan
    centre, height = box[:, 0] + box[:, 2] / 2, box[:, 3]
    second = lambda v: (v[:-2] - 2 * v[1:-1] + v[2:])[three] / height[1:-1][three]  # noqa: E731
    return float(np.median(np.abs(second(centre)))), float(np.median(np.abs(second(height))))


def match_noise(sensor: dict, target: tuple[float, float],
                measure: Callable[[dict], tuple[float, float]]) -> dict:
    """`sensor` with its per-frame box noise (KEYS) set so that the twin's jitter, `measure(sensor)` (centre, height),
    is the data's `target`; kept where the jitter cannot tell (no chains of three, or noise that adds none), and at
    most doubled."""
    quiet = measure({**sensor, **{key: 0.0 for key in KEYS}})
    noise = {key: float(sensor[key]) for key in KEYS}
    for _ in range(2):  # the quadrature step, then one correction from where it landed
        measured = measure({**sensor, **noise})
        for i, key in enumerate(KEYS):
            added, wanted = measured[i] ** 2 - quiet[i] ** 2, target[i] ** 2 - quiet[i] ** 2
            if noise[key] > 0 and added > 0 and math.isfinite(wanted):
                noise[key] = min(noise[key] * math.sqrt(max(wanted, 0.0) / added), 2.0 * float(sensor[key]))
    return {**sensor, **{key: round(value, 4) for key, value in noise.items()}}
