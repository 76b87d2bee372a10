"""Small hand-made scenarios for tests whose answers are known."""

import numpy as np

from mtt_sim import scenario
from mtt_sim.env import TrackingEnv

IDEAL = {"preset": "ideal", "clutter_rate": 0.0, "merge_prob": 0.0, "fragment_prob": 0.0}


def tiny(groups=None, occluders=(), sensor=None, **tables) -> scenario.Scenario:
    """A 200x100 flat topdown scene with still, unjittered targets and an ideal detector unless told otherwise."""
    raw = {
        "name": "Tiny",
        "render": {"width": 200, "height": 100, "background": "flat", **tables.pop("render", {})},
        "sensor": {**IDEAL, **(sensor or {})},
        "groups": groups or [{"count": 1, "speed": 0.0, "accel": 0.0, "size_jitter": 0.0, "region": [0.4, 0.4, 0.6, 0.6]}],
        "occluders": list(occluders),
        **tables,
    }
    return scenario.from_mapping(raw, "tiny")


def still(count=1, shape="ellipse", size=(40.0, 40.0), layer=0, name="g"):
    """A group of motionless targets."""
    return {"name": name, "count": count, "shape": shape, "size": list(size), "size_jitter": 0.0, "speed": 0.0,
            "accel": 0.0, "layer": layer, "region": [0.4, 0.4, 0.6, 0.6]}


def placed(sc: scenario.Scenario, positions, seed=0) -> TrackingEnv:
    """An env reset on `sc` with its targets moved to `positions` and the observation recomputed."""
    env = TrackingEnv(sc)
    env.reset(seed=seed)
    env.world.place(np.asarray(positions, float))
    env.observe()
    return env


def run_tracker(spec, env_id, config=None, seed=0, obs_mode="detections"):
    """One episode of tracker `spec` on `env_id` through gym.make: (the episode's metrics, the tracker)."""
    import gymnasium as gym

    import mtt_sim  # noqa: F401  (registers the env ids)
    import trackers

    env = gym.make(env_id, obs_mode=obs_mode, config=config or {})
    obs, info = env.reset(seed=seed)
    tracker = trackers.make(spec)
    tracker.reset(info)
    while True:
        obs, _, term, trunc, info = env.step(tracker.update(obs).to_action(env.action_space))
        if term or trunc:
            return info["metrics"], tracker


def fail_on_two(x):
    """A pool task: raises for 2, kills its own process for 3, else doubles."""
    import os
    import signal

    if x == 2:
        raise ValueError("two is not allowed")
    if x == 3:
        os.kill(os.getpid(), signal.SIGKILL)
    return 2 * x
