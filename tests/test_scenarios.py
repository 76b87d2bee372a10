"""Each shipped scenario runs and shows what its description promises, in measurable terms."""

import numpy as np
import pytest

from mtt_sim import TrackingEnv
from mtt_sim.sensor import CLUTTER

NO_TRACKS = {"ids": [], "boxes": np.zeros((0, 4))}


def run(key, steps, **kwargs):
    """Per-frame records of an episode: (truth, detections, frame mean, camera offset)."""
    env = TrackingEnv(key, **kwargs)
    obs, _ = env.reset(seed=0)
    out = []
    for _ in range(steps):
        frame = obs.get("frame")
        out.append((env.truth, env.detections, None if frame is None else float(frame.mean()),
                    env.renderer.camera.offset.copy()))
        obs, _, term, trunc, _ = env.step(NO_TRACKS)
        if term or trunc:
            break
    return env, out


RESOLUTION = {"crossing": (384, 288), "soccer": (720, 576), "umbrellas": (768, 576), "books": (640, 480),
              "skating": (320, 240), "mot17_like": (960, 540), "clutter_storm": (640, 480), "dense": (640, 480)}


@pytest.mark.parametrize("key", sorted(RESOLUTION))
def test_resolution_and_fifty_steps(key):
    env, rec = run(key, 50)
    assert (env.scenario.render.width, env.scenario.render.height) == RESOLUTION[key]
    assert len(rec) == 50


def test_crossing_two_walkers_are_cut_by_the_pole_hidden_by_the_sign_and_fragment():
    env, rec = run("crossing", 300)
    counts = [len(t) for t, *_ in rec]
    assert max(counts) == 2
    assert any(len(t.pieces) for t, *_ in rec)                      # the pole cuts a walker in two
    assert any((t.visibility < 0.3).any() for t, *_ in rec)          # the sign (or the other walker) hides one
    assert any(len(d.rows) > len(t) for t, d, *_ in rec)             # the foreground detector fragments
    assert env.world.standing


def test_soccer_many_alike_players_merge_in_the_foreground():
    env, rec = run("soccer", 100)
    assert all(len(t) == 22 for t, *_ in rec)
    colors = env.world.color.astype(float)
    assert np.ptp(colors[:11], axis=0).max() < 40                       # a team shares its kit
    assert any(len(d.rows) < len(t) for t, d, *_ in rec)             # touching players become one blob


def test_umbrellas_same_colour_different_texture_on_a_shaking_camera():
    env, rec = run("umbrellas", 220, obs_mode="detections")
    assert (env.world.color[0] == env.world.color[1]).all()
    assert env.world.texture_of_group.tolist() == [1, 2]
    offsets = np.array([o for *_, o in rec])
    assert np.ptp(offsets, axis=0).min() >= 2                           # the handheld camera shakes
    assert any((t.visibility < 0.9).any() for t, *_ in rec)          # the trunk hides an umbrella


def test_books_the_large_book_hides_a_small_one_completely_and_carries_the_top_one():
    env, rec = run("books", 400)
    vis = np.array([t.visibility for t, *_ in rec])                  # (frames, 4): ids 1, 2 small, 3 large, 4 top
    assert vis.shape == (400, 4) and env.world.shape_is_rect.all()
    assert (vis[:, :2] < 0.01).sum() >= 10                           # full occlusions of a small book
    assert np.allclose(vis[:, 2], 1 - 60 * 80 / (130 * 170), atol=0.02) and (vis[:, 3] == 1).all()


def test_skating_camera_follows_fast_skaters():
    env, rec = run("skating", 500)
    offsets = np.array([o for *_, o in rec])
    assert np.ptp(offsets[:, 0]) > 10 and np.abs(np.diff(offsets[:, 0])).max() <= 6   # pans, at most 6 px a frame
    centres = np.array([(t.boxes[:, 0] + t.boxes[:, 2] / 2).mean() for t, *_ in rec])
    inside = (offsets[:, 0] > 0) & (offsets[:, 0] < 640 - 320)       # away from the rink's ends the camera keeps up
    assert inside.sum() > 20 and np.median(np.abs(centres[inside] - 160)) < 10
    assert np.hypot(*env.world.vel.T).max() > 3


def test_mot17_like_crowd_enters_by_borders_and_doors_in_dim_light():
    env, rec = run("mot17_like", 150)
    assert len(rec[0][0]) >= 25 and env.world.births > 5
    assert max(m for *_, m, _ in rec) < 90                             # dim
    assert np.mean([(t.visibility < 1).sum() for t, *_ in rec]) > 1     # people occlude each other
    false = np.concatenate([d.sources == CLUTTER for _, d, *_ in rec])
    assert false.mean() > 0.05                                          # DPM's false positives


def test_clutter_storm_has_forty_false_alarms_a_frame():
    _, rec = run("clutter_storm", 100, obs_mode="detections")
    assert abs(np.mean([(d.sources == CLUTTER).sum() for _, d, *_ in rec]) - 40) < 2.5
    assert all(len(t) == 10 for t, *_ in rec)


def test_dense_two_hundred_touching_targets():
    _, rec = run("dense", 30, obs_mode="detections")
    assert all(len(t) == 200 for t, *_ in rec)
    assert np.mean([(t.visibility < 1).sum() for t, *_ in rec]) > 2
