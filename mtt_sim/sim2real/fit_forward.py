"""A camera going forward, read from tracklets alone (`mtt-sim fit-scene`): its rate, and the tracks without it.

A camera driven or carried forward makes every person grow and slide away from the image's middle column, the
faster the nearer (`mtt_sim.sim.forward`): over half a second, a tracklet's sideways speed is its growth rate times
its offset from the middle. Walkers on a still camera show no such link (people who come nearer grow, but slide
either way), so the link is the evidence: the correlation, over the tracklets' half-second windows, of growth times
offset with the sideways speed. On the eight shared MOT15 sequences it is 0.66-0.88 on the three cameras carried or
driven forward (ETH-Bahnhof, ETH-Sunnyday, KITTI-13, which has one tracklet a frame, too few for the common shift
that `fit_motion` reads) and at most 0.39 on the five still ones; MOVING_R sits between. The rate is the median over
the windows of the growth over the depth factor at the feet (the world's `far_scale` line): a person at depth factor
s grows at s times the rate, and walkers coming nearer or going away add growth of either sign, which the median
leaves out. Whoever holds still in the picture of a camera going forward walks at its pace (standing on the ground,
they would flow out with it): those are the camera's companions (`companions`).
"""

from __future__ import annotations

import numpy as np

from mtt_sim.sim import forward
from mtt_sim.sim2real.motion import STANDING

LAG = 0.5          # s: the windows' length
MOVING_R = 0.5     # the correlation from which the camera goes forward
MIN_WINDOWS = 20   # windows the evidence needs


def windows(tracks: dict[int, np.ndarray], width: float, frame_rate: float) -> np.ndarray:
    """Per half-second window of the tracks (per id, rows frame, foot x, foot y, height): its growth rate (1/s), its
    mean offset from the middle column (px), its sideways speed (px/s) and its mean feet row (px); (n, 4)."""
    lag = max(1, round(LAG * frame_rate))
    out = []
    for r in tracks.values():
        if len(r) <= lag:
            continue
        seconds = (r[lag:, 0] - r[:-lag, 0]) / frame_rate
        out.append(np.c_[np.log(r[lag:, 3] / r[:-lag, 3]) / seconds, (r[lag:, 1] + r[:-lag, 1]) / 2 - width / 2,
                         (r[lag:, 1] - r[:-lag, 1]) / seconds, (r[lag:, 2] + r[:-lag, 2]) / 2])
    return np.concatenate(out) if out else np.zeros((0, 4))


def evidence(values: np.ndarray) -> float:
    """The correlation of growth times offset with the sideways speed over `windows`' rows (0 where there are fewer
    than MIN_WINDOWS or nothing varies)."""
    if len(values) < MIN_WINDOWS:
        return 0.0
    pulled = values[:, 0] * values[:, 1]
    if np.std(pulled) == 0 or np.std(values[:, 2]) == 0:
        return 0.0
    return float(np.corrcoef(pulled, values[:, 2])[0, 1])


def rate(values: np.ndarray, height: float, far_scale: float) -> float:
    """`render.camera_forward` (1/s): the median over `windows`' rows of the growth over the depth factor at the
    feet of a world `height` px high with `far_scale`; 0 where it is not positive."""
    depth = np.maximum(forward.depth(values[:, 3], height, far_scale), 0.05)
    return max(0.0, float(np.median(values[:, 0] / depth)))


def companions(speeds: np.ndarray, length: int, frame_rate: float) -> int:
    """`render.camera_companions`: the people who hold still in the picture (one-second `speeds`, heights/s, of the
    tracklets' windows, below `motion.STANDING`) a frame, on average over a sequence of `length` frames, rounded.
    A person standing on the ground flows out of the picture: in the fitted scenes of the three shared cameras going
    forward, with everyone standing, the people moved a median 0.18-1.27 heights/s, and 0.00-0.12 of their windows
    fell below STANDING. ETH-Sunnyday's two people walking ahead of the camera through its 25 s give 438 of its
    people's 455 standing windows."""
    windows = max(length - round(frame_rate), 1)  # the frames at which a one-second window ends
    return int(round(np.count_nonzero(speeds < STANDING) / windows))


def without(tracks: dict[int, np.ndarray], extent, far_scale: float, per_second: float,
            frame_rate: float) -> dict[int, np.ndarray]:
    """The tracks with the forward camera's flow taken out of their foot points: each step's displacement less the
    flow's, summed from the first point (the people's own walk, for the walking model's fit)."""
    out = {}
    for i, r in tracks.items():
        r = r.copy()
        if len(r) > 1:
            gap = np.diff(r[:, 0])[:, None]
            flowed = forward.flow(r[:-1, 1:3], extent, far_scale, per_second / frame_rate) - r[:-1, 1:3]
            own = np.diff(r[:, 1:3], axis=0) - flowed * gap  # a gap of several frames: the flow of one, times it
            r[1:, 1:3] = r[0, 1:3] + np.cumsum(own, axis=0)
        out[i] = r
    return out
