"""The walking model (`mtt_sim.sim.walkers`) fitted to real ground truth: the parameters whose walkers show the real
people's statistics (`mtt_sim.sim2real.motion`).

Three parts are read off the data directly, over whole one-second windows of every track: the desired speed and its
spread (the median speed of the windows where a person walks, and the spread of the people's own medians), and the
stop and go rates (how often a walking second is followed by a standing one, and the reverse). The velocity's
relaxation time and noise have no direct reading: they are chosen on a grid, by simulating the model's walkers alone
(no world, no camera) and matching, in the least squares of their logarithms, the real median speed, deviation from
constant velocity and turn, and the standing share (the relaxation sets how fast a person stops): the best point of
a grid, refined with the desired speed by Nelder-Mead (the measured speed of a noisy walker is not its desired one).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import replace
from typing import Callable, Iterable, Sequence

import numpy as np
from scipy.optimize import minimize

from mtt_sim.sim.config import WalkConfig
from mtt_sim.sim.walkers import Walkers
from mtt_sim.sim2real.motion import STANDING, track_rows, window_values

RELAX = (0.25, 0.5, 1.0, 2.0, 4.0)               # s: the grid of relaxation times tried
NOISE = tuple(np.round(np.geomspace(0.02, 1.5, 15), 4))  # heights/s/sqrt(s): the grid of noise strengths


def seconds(frames, frame_rate: float) -> list[np.ndarray]:
    """Per track, its speed over each whole, non-overlapping one-second window (heights per second)."""
    n = max(1, round(frame_rate))
    out = []
    for rows in track_rows(frames).values():
        feet, height = rows[::n, 1:3], rows[::n, 3]
        if len(feet) > 1:
            out.append(np.hypot(*(feet[1:] - feet[:-1]).T) / ((height[1:] + height[:-1]) / 2))
    return out


def direct(sources: Sequence[tuple[list, float]]) -> dict:
    """The parameters read off (frames, frame rate) sources directly: speed, speed_jitter, stop_rate, go_rate."""
    per_track = [s for frames, rate in sources for s in seconds(frames, rate)]
    walking = np.concatenate([s[s >= STANDING] for s in per_track]) if per_track else np.zeros(0)
    own = [np.median(s[s >= STANDING]) for s in per_track if (s >= STANDING).sum() >= 3]
    stops = goes = walk_time = stand_time = 0
    for s in per_track:
        stand = s < STANDING
        stops += int(np.sum(~stand[:-1] & stand[1:]))
        goes += int(np.sum(stand[:-1] & ~stand[1:]))
        walk_time += int(np.sum(~stand[:-1]))
        stand_time += int(np.sum(stand[:-1]))
    if not len(walking):
        raise ValueError("no person walks for a whole second in these sequences: nothing to fit the walkers to")
    return {"speed": float(np.median(walking)), "speed_jitter": round(float(np.std(np.log(own))), 4) if len(own) > 1
            else 0.3, "stop_rate": round(stops / max(walk_time, 1), 4),
            "go_rate": round(goes / stand_time, 4) if stand_time else 1.0}


def simulate(config: WalkConfig, frame_rate: float, people: int = 150, duration: float = 20.0,
             seed: int = 0) -> list[tuple[np.ndarray, np.ndarray]]:
    """Frames of (ids, boxes) of `people` walkers of `config` alone, each heading for a far goal, boxes 1 tall."""
    rng = np.random.default_rng(seed)
    walkers = Walkers(config, frame_rate)
    heading = rng.uniform(0, 2 * math.pi, people)
    goal = 1e6 * np.c_[np.cos(heading), np.sin(heading)]
    desired = np.array([walkers.desired_speed(rng) for _ in range(people)])
    pos, height = np.zeros((people, 2)), np.ones(people)
    vel = goal / 1e6 * (desired * walkers.dt)[:, None]
    standing = rng.random(people) < walkers.standing_share
    ids, frames = np.arange(people), []
    for _ in range(round(duration * frame_rate)):
        frames.append((ids, np.c_[pos[:, 0] - 0.2, pos[:, 1] - 1.0, np.full(people, 0.4), height]))
        vel, standing = walkers.step(vel, pos, goal, desired, height, standing, rng)
        pos = pos + vel
    return frames


def fit(sources: Iterable[tuple[list, float]], frame_rate: float = 25.0) -> WalkConfig:
    """The walking model fitted to (frames, frame rate) sources of real scored ground truth, for scenes at
    `frame_rate` frames per second."""
    sources = list(sources)
    target = statistics([window_values(frames, rate) for frames, rate in sources])
    base = replace(WalkConfig(model="langevin"), **direct(sources))

    def with_(relax: float, noise: float, speed: float) -> WalkConfig:
        return replace(base, relax=float(relax), noise=float(noise), speed=float(speed))

    return with_(*np.round(search(with_, base.speed, target, frame_rate), 4))


def search(with_: Callable[[float, float, float], WalkConfig], speed: float, target: np.ndarray, frame_rate: float,
           people: int = 150, duration: float = 20.0, seed: int = 0) -> np.ndarray:
    """The relaxation, noise and desired speed whose walkers (`with_` of them, `simulate`d) best show `target`
    (`statistics`), in the least squares of the logarithms: the best point of the RELAX x NOISE grid at the desired
    speed `speed`, refined with the speed by Nelder-Mead."""
    def miss(x) -> float:
        got = statistics([window_values(simulate(with_(*np.exp(x)), frame_rate, people, duration, seed), frame_rate)])
        return float(np.sum(np.log(np.maximum(got, 1e-3) / np.maximum(target, 1e-3)) ** 2))

    start = min(itertools.product(RELAX, NOISE), key=lambda rn: miss(np.log([*rn, speed])))
    found = minimize(miss, np.log([*start, speed]), method="Nelder-Mead",
                     options={"xatol": 0.02, "fatol": 1e-4, "maxfev": 120})
    return np.exp(found.x)


def statistics(values: list[dict]) -> np.ndarray:
    """What the walkers are matched on: the median speed, deviation and turn, and the standing share, over every
    window of `values` (`motion.window_values` of each source; 0 where there is none)."""
    joined = {k: np.concatenate([v[k] for v in values]) for k in ("speed", "deviation", "turning")}
    med = lambda v: float(np.median(v)) if len(v) else 0.0  # noqa: E731
    return np.array([med(joined["speed"]), med(joined["deviation"]), med(joined["turning"]),
                     float(np.mean(joined["speed"] < STANDING)) if len(joined["speed"]) else 0.0])
