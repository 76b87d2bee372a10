"""Stable-Baselines3 PPO on `mtt_sim/TrackManagement-v0`, with the [rl] extra (torch is large, so it is optional):
train on mot17_like with the dpm detector, then compare the PPO agent's episodes with SORT's rules on held-out seeds.

    pip install 'mtt-sim[rl]'
    python docs/experiments/ppo_management.py 50000
"""

import sys
import time

import gymnasium as gym
import numpy as np
from mtt_sim.trackers.parts.management import SORT_RULES, decisions
from stable_baselines3 import PPO
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import SubprocVecEnv

import mtt_sim  # noqa: F401  (registers the env ids)

ENV = {"scenario": "mot17_like", "config": {"sensor.preset": "dpm", "env.max_steps": 200}, "max_candidates": 32}


def sort_rules(obs) -> np.ndarray:
    """SORT's own decisions, as the env's action."""
    n = int(obs["mask"].sum())
    action = np.zeros((len(obs["mask"]), 2), np.int8)
    action[:n] = np.stack(decisions(SORT_RULES, obs["features"][:n]), axis=1)
    return action.ravel()


def episode(act, seed: int) -> dict:
    env = gym.make("mtt_sim/TrackManagement-v0", **ENV)
    obs, _ = env.reset(seed=seed)
    while True:
        obs, _, terminated, truncated, info = env.step(act(obs))
        if terminated or truncated:
            return info["metrics"]


def main() -> None:
    steps = int(sys.argv[1]) if len(sys.argv) > 1 else 50_000
    start = time.perf_counter()
    envs = make_vec_env("mtt_sim/TrackManagement-v0", n_envs=8, seed=1000, env_kwargs=ENV, vec_env_cls=SubprocVecEnv)
    model = PPO("MultiInputPolicy", envs, n_steps=256, batch_size=256, seed=0, verbose=0)
    model.learn(steps)
    print(f"PPO: {steps} steps in {time.perf_counter() - start:.0f} s")
    for seed in range(3):
        sort = episode(sort_rules, seed)
        ppo = episode(lambda obs: model.predict(obs, deterministic=True)[0], seed)
        print(f"seed {seed}: MOTA sort {sort['MOTA']:.3f} ppo {ppo['MOTA']:.3f}; HOTA sort {sort['HOTA']:.3f} "
              f"ppo {ppo['HOTA']:.3f}")


if __name__ == "__main__":
    main()
