"""One episode, frame by frame: the loop every runner of the env shares (experiments, exports, statistics, crops,
stills, timings), so that they all reset, answer and stop alike."""

from __future__ import annotations

import time
from typing import Iterator

import gymnasium as gym

from mtt_sim.env import NO_TRACKS
from mtt_sim.trackers import Tracker, Tracks


class Episode:
    """One agent (or none, which reports no tracks) on its own env, from a seeded reset to the episode's end or
    `steps` steps (default: the env's env.max_steps).

    Each frame the agent answers the current observation (`answer`), then the env steps with that answer
    (`advance`). Iterating does both, pausing between them: at each pause `obs`, `tracks` and `action` are the
    current frame's and the env still shows that frame (its truth, its image), which is when callers read the truth,
    save a frame or draw the answer. The agent's time and the env's are kept apart: env time runs from the answer to
    the end of the step, so what the caller draws in between counts as the env's."""

    def __init__(self, env: gym.Env, seed: int = 0, agent: Tracker | None = None, steps: int | None = None):
        self.env, self.agent = env, agent
        self.obs, self.info = env.reset(seed=seed)
        if agent is not None:
            agent.reset(self.info)
        self.limit = steps or env.unwrapped.config.env.max_steps
        self.steps = 0  # env steps taken: the current frame's index
        self.done = False
        self.tracks: Tracks | None = None
        self.action = NO_TRACKS
        self.reward = 0.0  # the last step's
        self.tracker_time = self.env_time = 0.0
        self._answered = time.perf_counter()

    def answer(self) -> None:
        """The agent's tracks for the current frame and the action they make (no tracks without an agent)."""
        start = time.perf_counter()
        self.tracks = self.agent.update(self.obs) if self.agent is not None else None
        self._answered = time.perf_counter()
        self.tracker_time += self._answered - start
        self.action = self.tracks.to_action(self.env.action_space) if self.tracks is not None else NO_TRACKS

    def advance(self) -> None:
        """Step the env with the answer; done when the episode ends or after `limit` steps."""
        self.obs, self.reward, terminated, truncated, _ = self.env.step(self.action)
        self.env_time += time.perf_counter() - self._answered
        self.steps += 1
        self.done = terminated or truncated or self.steps >= self.limit

    def __iter__(self) -> Iterator[Episode]:
        """Itself at every frame, once the agent has answered it and before the env steps."""
        while not self.done:
            self.answer()
            yield self
            self.advance()
