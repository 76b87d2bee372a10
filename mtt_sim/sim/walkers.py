"""Walkers that move like people: a stochastic walking model fitted to real trajectories.

Velocity is a Langevin (Ornstein-Uhlenbeck) process relaxing toward a desired velocity with noise, the model
Corbetta et al. (PRE 2017) fitted to real walkers: dv = (v_d - v) / relax dt + noise dW. The desired velocity points
at the person's goal (an exit door, or the far side of the world) at the person's own desired speed. People also stop,
wait and walk on: a two-state process, walking to standing at `stop_rate` and back at `go_rate` per second; a standing
person's desired velocity is zero and their noise `stand_noise` times smaller (they sway, they do not drift).
Avoidance is left to the physics (pymunk's soft contacts): the statistics the model is fitted to (speed, deviation
from constant velocity, standing, turning) do not constrain it, and contacts already keep people apart.

Units are people's own: speeds in body heights per second, times in seconds, so one parameter set describes walkers
seen by any camera at any frame rate; the world converts with each person's height (its near-edge size) and the
scene's frame rate. The fit (`fit`) measures the same statistics on real ground truth (`mtt_sim.sim2real.motion`) and
chooses the parameters that reproduce them.
"""

from __future__ import annotations

import math

import numpy as np

from mtt_sim.sim.config import WalkConfig


class Walkers:
    """The walking model of `config` at `frame_rate` frames per second, stepping the velocities of a world's people."""

    def __init__(self, config: WalkConfig, frame_rate: float):
        self.cfg, self.dt = config, 1.0 / frame_rate
        self.p_stop = 1.0 - math.exp(-config.stop_rate * self.dt)
        self.p_go = 1.0 - math.exp(-config.go_rate * self.dt)
        self.standing_share = config.stop_rate / max(config.stop_rate + config.go_rate, 1e-9)  # the two-state
        # process's stationary share: the chance that a person seen at an arbitrary moment stands

    def desired_speed(self, rng: np.random.Generator) -> float:
        """A new person's desired speed, heights per second (log-normal about `speed`, `speed_jitter` its spread)."""
        return self.cfg.speed * math.exp(self.cfg.speed_jitter * rng.normal())

    def step(self, vel: np.ndarray, pos: np.ndarray, goal: np.ndarray, desired: np.ndarray, height: np.ndarray,
             standing: np.ndarray, rng: np.random.Generator, staying: np.ndarray | None = None
             ) -> tuple[np.ndarray, np.ndarray]:
        """One frame: the new ground velocities (px a frame) and who stands, from the current ones, positions, goals,
        desired speeds (heights/s), heights (px) and standing flags; people `staying` (flags) stand throughout."""
        n = len(vel)
        u = rng.random(n)
        standing = np.where(standing, u >= self.p_go, u < self.p_stop)
        if staying is not None:
            standing |= staying
        to_goal = goal - pos
        direction = to_goal / np.maximum(np.hypot(*to_goal.T), 1e-9)[:, None]
        per_frame = (height * self.dt)[:, None]  # heights per second -> px per frame
        wanted = np.where(standing[:, None], 0.0, direction * desired[:, None] * per_frame)
        noise = self.cfg.noise * math.sqrt(self.dt) * np.where(standing, 1.0 / self.cfg.stand_noise, 1.0)
        kick = rng.normal(size=(n, 2)) * (noise[:, None] * per_frame)
        return vel + (wanted - vel) * min(1.0, self.dt / self.cfg.relax) + kick, standing
