"""The colour + texture particle filter (Li, Zhang and Li 2007), end to end on the umbrellas scene."""

import gymnasium as gym
import numpy as np
import pytest

import mtt_sim  # noqa: F401  (registers the env ids)
from mtt_sim import trackers
from helpers import leaving_book, run_tracker
from mtt_sim.trackers.parts.particles import systematic_resample


def episode(spec, steps=200, seed=0):
    return run_tracker(spec, "mtt_sim/Umbrellas-v0", {"env.max_steps": steps}, seed, obs_mode="frame+detections")


def test_fusion_holds_the_target_where_colour_alone_jumps_to_the_alike_umbrella():
    # the paper's experiment on seed 0: two umbrellas of one colour cross at about frame 120
    fused, _ = episode("pf")
    colour, _ = episode("pf:alpha=1.0")
    assert fused["MOTA"] > 0.8 and fused["IDSW"] == 0
    assert colour["MOTA"] < 0.3


def test_runs_are_reproducible_and_debug_shows_weighted_particles():
    a, tracker = episode("pf:particles=20", steps=20)
    b, _ = episode("pf:particles=20", steps=20)
    assert a == b
    clouds = tracker.debug()
    assert len(clouds) == 2 and clouds[0]["xy"].shape == (20, 2) and clouds[0]["weights"].sum() == pytest.approx(1)


def test_needs_the_frame():
    env = gym.make("mtt_sim/Umbrellas-v0", obs_mode="detections")
    obs, info = env.reset(seed=0)
    tracker = trackers.make("pf")
    tracker.reset(info)
    with pytest.raises(ValueError, match="reads the video frame"):
        tracker.update(obs)


def test_systematic_resampling_keeps_heavy_particles():
    rng = np.random.default_rng(0)
    picks = systematic_resample(np.array([[0.0, 1.0, 0.0, 0.0], [0.25, 0.25, 0.25, 0.25]]), rng)
    assert picks[0].tolist() == [1, 1, 1, 1] and sorted(picks[1].tolist()) == [0, 1, 2, 3]


def test_particles_stay_inside_the_image_when_their_target_leaves_it():
    """The book runs out of the right edge; the particles' velocities would carry them off without bound."""
    _, tracker = run_tracker("pf", leaving_book(), obs_mode="frame+detections")
    xy = tracker.particles[:, :, :2]
    assert ((xy >= 0) & (xy <= [200, 100])).all() and (xy[..., 0] > 150).any()
