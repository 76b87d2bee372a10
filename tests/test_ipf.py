"""Seed 002's interactive particle filter: the conflict set by hand, and runs through gym.make."""

import numpy as np

from helpers import run_tracker
from trackers.ipf import conflict_set


def test_conflict_set_on_hand_placed_regions():
    sizes = np.array([[10.0, 10.0], [10.0, 10.0], [4.0, 4.0]])
    centres = np.array([
        [[0.0, 0.0], [100.0, 100.0]],   # target 0: one particle at the origin, one far away
        [[1.0, 0.0], [50.0, 50.0]],     # target 1: overlaps target 0's first particle by 9/10 > 0.75
        [[52.0, 50.0], [300.0, 0.0]],   # target 2: small; inside target 1's second particle entirely
    ])
    s = conflict_set(centres, sizes, 0.75)
    assert s.tolist() == [[True, False], [True, True], [True, False]]
    shifted = centres.copy()
    shifted[1, 0] = [3.0, 0.0]          # overlap 7/10 of the smaller region: no longer a conflict
    assert conflict_set(shifted, sizes, 0.75)[:, 0].tolist() == [False, False, True]  # target 2 still inside 1's


def test_runs_and_is_reproducible_with_and_without_interaction():
    a, tracker = run_tracker("ipf:particles=30", "mtt_sim/Books-v0", {"env.max_steps": 15}, obs_mode="frame+detections")
    b, _ = run_tracker("ipf:particles=30", "mtt_sim/Books-v0", {"env.max_steps": 15}, obs_mode="frame+detections")
    c, _ = run_tracker("ipf:particles=30,interactive=false", "mtt_sim/Books-v0", {"env.max_steps": 15},
                       obs_mode="frame+detections")
    assert a == b and a["num_frames"] == c["num_frames"] == 15 and a["TP"] > 30
    clouds = tracker.debug()
    assert len(clouds) == 4 and clouds[0]["xy"].shape == (30, 2)
    np.testing.assert_allclose([cl["weights"].sum() for cl in clouds], 1.0)
