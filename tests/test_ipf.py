"""The interactive particle filter (Liu et al. 2011): the conflict set by hand, and runs through gym.make."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mtt_sim import trackers
from helpers import EXPERIMENTS, leaving_book, run_tracker, tiny
from mtt_sim.env import NO_TRACKS, TrackingEnv
from mtt_sim.trackers.ipf import conflict_set


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


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 10**6), st.integers(1, 6), st.integers(1, 12), st.floats(0.05, 1.0), st.booleans())
def test_conflict_set_equals_the_plain_pair_loop(seed, k, n, ratio, whole_pixels):
    rng = np.random.default_rng(seed)
    sizes = rng.uniform(4, 30, (k, 2))
    sizes = np.round(sizes) if whole_pixels else sizes
    centres = rng.uniform(0, 40, (k, 1, 2)) + rng.normal(0, 6, (k, n, 2))
    expected = np.zeros((k, n), bool)
    for a, i, b, j in itertools.product(range(k), range(n), range(k), range(n)):
        if a != b:
            lo = np.maximum(centres[a, i] - sizes[a] / 2, centres[b, j] - sizes[b] / 2)
            hi = np.minimum(centres[a, i] + sizes[a] / 2, centres[b, j] + sizes[b] / 2)
            inter = np.prod(np.clip(hi - lo, 0, None))
            expected[a, i] |= inter > ratio * min(np.prod(sizes[a]), np.prod(sizes[b]))
    np.testing.assert_array_equal(conflict_set(centres, sizes, ratio), expected)


class _StepWithoutNoise:
    """A generator whose Gaussian draws are zero (the Brownian step vanishes), its other draws the real ones."""

    def __init__(self, rng):
        self.rng = rng

    def normal(self, loc, scale, size):
        return np.zeros(size)

    def random(self, size):
        return self.rng.random(size)


@pytest.mark.parametrize("spec", ["ipf", "pcpf"])
def test_propagation_from_the_estimate_or_from_the_resampled_particles(spec):
    """Without the Brownian step, propagate=estimate puts every particle on the prediction; propagate=resample keeps
    previous particles, drawn by weight (heavy ones repeated), moved as the prediction moved."""
    env = TrackingEnv("books")
    obs, info = env.reset(seed=0)
    second = env.step(NO_TRACKS)[0]
    for propagate in ("estimate", "resample"):
        tracker = trackers.make(f"{spec}:propagate={propagate},particles=40")
        tracker.reset(info)
        tracker.update(obs)
        before = tracker._cloud[0].copy()
        prediction = tracker._predict().copy()
        moved = prediction - tracker.estimates
        tracker.rng = _StepWithoutNoise(tracker.rng)
        tracker.update(second)
        after = tracker._cloud[0]
        if propagate == "estimate":
            assert np.array_equal(after, np.broadcast_to(prediction[:, None], after.shape))
        else:
            for t in range(len(after)):
                assert all(any(np.allclose(p, q + moved[t]) for q in before[t]) for p in after[t])
            assert max(len(after[t]) - len(np.unique(after[t], axis=0)) for t in range(len(after))) > 0


def test_the_step_spread_reads_delta_as_a_deviation_or_as_a_variance():
    info = {"init_ids": np.array([1]), "init_boxes": np.array([[0.0, 0.0, 80.0, 125.0]]), "image_size": (640, 480)}
    std, variance = trackers.make("ipf"), trackers.make("ipf:spread=variance")
    std.reset(info)
    variance.reset(info)
    assert std.sigma[0] == 50.0 and variance.sigma[0] == np.sqrt(50.0)   # delta = sqrt(80 x 125) / 2 = 50


def test_runs_and_is_reproducible_with_and_without_interaction():
    a, tracker = run_tracker("ipf:particles=30", "mtt_sim/Books-v0", {"env.max_steps": 15}, obs_mode="frame+detections")
    b, _ = run_tracker("ipf:particles=30", "mtt_sim/Books-v0", {"env.max_steps": 15}, obs_mode="frame+detections")
    c, _ = run_tracker("ipf:particles=30,interactive=false", "mtt_sim/Books-v0", {"env.max_steps": 15},
                       obs_mode="frame+detections")
    assert a == b and a["num_frames"] == c["num_frames"] == 15 and a["TP"] > 30
    clouds = tracker.debug()
    assert len(clouds) == 4 and clouds[0]["xy"].shape == (30, 2)
    np.testing.assert_allclose([cl["weights"].sum() for cl in clouds], 1.0)


def final_errors(sc, spec):
    """Per target id, the distance from its track's centre to its true centre at the last frame, and the smallest
    visibility the small book reached."""
    env = TrackingEnv(sc, obs_mode="frame+detections")
    obs, info = env.reset(seed=0)
    tracker = trackers.make(spec)
    tracker.reset(info)
    least = 1.0
    while True:
        tracks = tracker.update(obs)
        obs, _, term, trunc, _ = env.step(tracks.to_action(env.action_space))
        least = min(least, float(env.truth.visibility[0]))
        if term or trunc:
            break
    truth = {int(i): b[:2] + b[2:] / 2 for i, b in zip(env.truth.ids, env.truth.boxes)}
    return {int(i): float(np.hypot(*(b[:2] + b[2:] / 2 - truth[int(i)]))) for i, b in zip(tracks.ids, tracks.boxes)}, least


def test_interactive_filter_keeps_a_look_alike_book_through_complete_occlusion_where_independent_filters_lose_it():
    # the hidden book's colour is close to its occluder's: an independent filter's particles latch onto the occluder
    # and leave with it; the interactive filter sees the occluder's template explain them better (eq. 4) and holds on
    sc = str(EXPERIMENTS / "lookalike_crossing.toml")
    kept, least = final_errors(sc, "ipf")
    lost, _ = final_errors(sc, "ipf:interactive=false")
    assert least == 0.0                       # the small book was completely hidden
    assert max(kept.values()) < 10           # both ids end on their own books
    assert lost[1] > 50 and lost[2] < 10     # the independent filter's small book left with the large one


def test_path_consistency_baseline_coasts_through_a_static_occluder():
    # a book of its own colour passes behind a grey pillar; pcpf carries it on its velocity, ipf's Brownian filter
    # stays where it last saw it
    book = {"name": "b", "count": 1, "shape": "rect", "size": [30.0, 30.0], "size_jitter": 0.0, "speed": 2.0,
            "speed_jitter": 0.0, "heading": 0.0, "heading_jitter": 0.0, "accel": 0.0, "region": [0.2, 0.5, 0.201, 0.501],
            "color": [40, 160, 60], "similarity": 1.0, "texture": "checks"}
    sc = tiny(groups=[book], occluders=[{"rect": [120.0, 40.0, 90.0, 120.0], "color": [90, 90, 90]}],
              render={"width": 300, "height": 200, "background": "noise", "noise": 3.0}, world={"walls": False},
              env={"max_steps": 110})
    coasted, least = final_errors(sc, "pcpf")
    stayed, _ = final_errors(sc, "ipf")
    assert least == 0.0 and coasted[1] < 10 and stayed[1] > 30


def test_occlusion_windows_see_the_interactive_filter_take_a_hidden_book_back_and_independent_filters_not():
    sc = str(EXPERIMENTS / "lookalike_crossing.toml")
    kept, lost = (run_tracker(spec, sc, obs_mode="frame+detections")[0]  # 90 steps: room for the window
                  for spec in ("ipf", "ipf:interactive=false"))
    assert kept["Occlusions"] == lost["Occlusions"] == 1
    assert kept["Reacquired"] == 1.0 and lost["Reacquired"] == 0.0
    assert kept["HiddenCentreError"] < lost["HiddenCentreError"]


@pytest.mark.parametrize("spec", ["pcpf", "ipf"])
def test_estimates_stay_inside_the_image_when_a_target_leaves_it(spec):
    """A book runs out of the right edge; pcpf coasts on its velocity and ipf's particles wander. The filters' state
    is a position in the image, so the estimate stops at the border; it used to run past the action space."""
    _, tracker = run_tracker(spec, leaving_book(), obs_mode="frame+detections")
    assert ((tracker.estimates >= 0) & (tracker.estimates <= [200, 100])).all()
