"""A fingerprint of the project's behaviour, to show that a change which should alter nothing altered nothing.

Hashes (sha256, first 16 hex digits) of: every shipped scenario's observations, rewards, frame counts and episode
metrics for seeds 0 and 1 (SORT answering, 100 frames); and, given the shared data folder, every registered
tracker's tracks and metrics on each MOT15 sequence and the twin of TUD-Campus. Prints one line per item and a total.

    python docs/experiments/fingerprint.py [../shared/data] > before.txt
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

import mtt_sim
from mtt_sim import trackers

STEPS = 100


def _digest(parts) -> str:
    h = hashlib.sha256()
    for p in parts:
        h.update(np.ascontiguousarray(p).tobytes() if isinstance(p, np.ndarray) else
                 json.dumps(p, sort_keys=True, default=str).encode())
    return h.hexdigest()[:16]


def episode(env, spec: str, seed: int, steps: int | None) -> str:
    agent = trackers.make(spec)
    obs, info = env.reset(seed=seed)
    agent.reset(info)
    parts = [info["init_ids"], info["init_boxes"]]
    k = 0
    while steps is None or k < steps:
        tracks = agent.update(obs)
        action = tracks.to_action(env.action_space)
        parts += [obs["detections"], action["ids"], action["boxes"]] + ([obs["frame"]] if "frame" in obs else [])
        obs, reward, terminated, truncated, step_info = env.step(action)
        parts += [reward, step_info["frame"]]
        k += 1
        if terminated or truncated:
            break
    metrics = env.unwrapped.metrics
    parts += [metrics.summary(), metrics.per_target()]
    return _digest(parts)


def main(data: str | None) -> None:
    lines = []
    for key, env_id in sorted(mtt_sim.env_ids().items()):
        if key == "replay":
            continue
        for seed in (0, 1):
            env = gym.make(env_id)
            lines.append(f"scenario {key} seed {seed}: {episode(env, 'sort', seed, STEPS)}")
    if data:
        folders = sorted(Path(data, "mot15").iterdir())
        ours = [n for n in sorted(trackers.available()) if not n.startswith("roboflow:")]  # peers: docs/peers.md
        for spec in [*ours, "lmb:reid=false"]:  # lmb's re-id reads frames, which these lack
            for folder in folders:
                try:
                    env = mtt_sim.TrackingEnv(sequence=folder)
                    result = episode(env, spec, 0, None)
                except Exception as err:  # noqa: BLE001  (a tracker that cannot run here is part of the fingerprint)
                    result = f"error {type(err).__name__}: {str(err).splitlines()[0][:80]}"
                lines.append(f"tracker {spec} on {folder.name}: {result}")
                print(lines[-1], file=sys.stderr, flush=True)
        twin = mtt_sim.TrackingEnv(sequence=Path(data, "mot15", "TUD-Campus"), config={"sensor.model": "synthetic"})
        lines.append(f"twin TUD-Campus sort seed 1: {episode(twin, 'sort', 1, None)}")
    print("\n".join(lines))
    print(f"total: {_digest(lines)}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
