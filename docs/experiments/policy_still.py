"""What the shipped `learned` policy decides on a walking camera, drawn: frame FRAME of `mot17_moving` (seed 0)
through the track-management env, each of SORT's candidates outlined by the policy's decision (green reported,
yellow kept unreported, red dropped).

    python docs/experiments/policy_still.py docs/learned_decisions_mot17_moving.jpg [FRAME]
"""

import sys

import cv2
import numpy as np

from mtt_sim.learn.management_env import TrackManagementEnv
from mtt_sim.trackers.learned import SHIPPED_POLICY, load_policy
from mtt_sim.trackers.parts.management import decisions


def main() -> None:
    out, frame = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 120
    weights = load_policy(SHIPPED_POLICY)
    env = TrackManagementEnv("mot17_moving", render_mode="rgb_array")
    obs, _ = env.reset(seed=0)
    for _ in range(frame):
        n = int(obs["mask"].sum())
        action = np.zeros((env.max_candidates, 2), np.int8)
        report, keep = decisions(weights, obs["features"][:n])
        action[:n, 0], action[:n, 1] = report, keep
        obs, *_ = env.step(action)
    cv2.imwrite(out, cv2.cvtColor(env.render(), cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 85])
    env.close()


if __name__ == "__main__":
    main()
