"""The README's stills: each paper's tracker on the scene it was built for, ByteTrack on mot17_like, and the
side-by-side GIF.

Each still is what `env.render()` shows once the agent hands its tracker's drawings to the env (the hand-over any
Gym agent can use, `RecordVideo` included). Run from the repository root:

    python docs/experiments/stills.py
"""

from __future__ import annotations

import cv2
import gymnasium as gym

import mtt_sim  # noqa: F401  (registers the env ids)
import trackers
from mtt_sim.experiment import run_episodes

STILLS = [  # (env id, tracker, seed, frame, render scale, file)
    ("mtt_sim/Crossing-v0", "jpda", 1, 60, 2, "docs/still_jpda_crossing.jpg"),
    ("mtt_sim/Umbrellas-v0", "pf", 0, 40, 1, "docs/still_pf_umbrellas.jpg"),
    ("mtt_sim/Books-v0", "ipf", 0, 45, 1, "docs/still_ipf_books.jpg"),
    ("mtt_sim/Mot17Like-v0", "lmb", 0, 60, 1, "docs/still_lmb_mot17_like.jpg"),
    ("mtt_sim/Mot17Like-v0", "bytetrack", 0, 120, 1, "docs/demo.jpg"),
]


def still(env_id: str, spec: str, seed: int, frame: int, scale: int, path: str) -> None:
    tracker = trackers.make(spec)
    env = gym.make(env_id, render_mode="rgb_array", render_scale=scale,
                   obs_mode="frame+detections" if tracker.needs_frame else "detections")
    obs, info = env.reset(seed=seed)
    tracker.reset(info)
    for _ in range(frame + 1):
        tracks = tracker.update(obs)
        env.unwrapped.remember_tracks(tracks.ids, tracks.boxes, tracker.debug(), spec)
        obs, *_ = env.step(tracks.to_action(env.action_space))
    cv2.imwrite(path, cv2.cvtColor(env.render(), cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 85])
    env.close()


if __name__ == "__main__":
    for args in STILLS:
        still(*args)
        print(args[-1])
    run_episodes("crossing", ["sort", "jpda"], seed=1, video="docs/compare_sort_jpda_crossing.gif", steps=100)
    print("docs/compare_sort_jpda_crossing.gif")
