"""Each shipped scenario runs and shows what its description promises, in measurable terms."""

import numpy as np
import pytest

from mtt_sim import TrackingEnv

from mtt_sim.lab.episode import Episode
from mtt_sim.sim2real import motion, truth_statistics
from mtt_sim.core.frame import CLUTTER, Truth
from mtt_sim.core.settings import ConfigError
from mtt_sim.sim.scenario import load

def run(key, steps, **kwargs):
    """Per-frame records of an episode of seed 0 without tracks: (truth, detections, frame mean, camera offset)."""
    env = TrackingEnv(key, **kwargs)
    out = []
    for now in Episode(env, steps=steps):
        frame = now.obs.get("frame")
        out.append((env.truth, env.detections, None if frame is None else float(frame.mean()),
                    env.source.renderer.camera.offset.copy()))
    return env, out


RESOLUTION = {"crossing": (384, 288), "soccer": (720, 576), "umbrellas": (768, 576), "books": (640, 480),
              "skating": (320, 240), "mot17_like": (960, 540), "clutter_storm": (640, 480), "dense": (640, 480)}


@pytest.mark.parametrize("key", sorted(RESOLUTION))
def test_resolution_and_fifty_steps(key):
    env = TrackingEnv(key)
    episode = Episode(env, steps=50)
    width, height = RESOLUTION[key]
    assert episode.info["image_size"] == (width, height)
    for now in episode:  # every frame of that size, every observation inside the space the env declares
        assert now.obs["frame"].shape == (height, width, 3) and env.observation_space.contains(now.obs)
    assert episode.steps == 50  # fifty frames: the scene did not end before


def test_crossing_two_walkers_are_cut_by_the_pole_hidden_by_the_sign_and_fragment():
    env, rec = run("crossing", 300)
    counts = [len(t) for t, *_ in rec]
    assert max(counts) == 2
    assert any(len(t.pieces) for t, *_ in rec)                      # the pole cuts a walker in two
    assert any((t.visibility < 0.3).any() for t, *_ in rec)          # the sign (or the other walker) hides one
    assert any(len(d.rows) > len(t) for t, d, *_ in rec)             # the foreground detector fragments
    assert env.source.world.standing


def test_soccer_many_alike_players_merge_in_the_foreground():
    env, rec = run("soccer", 100)
    assert all(len(t) == 22 for t, *_ in rec)
    colors = env.source.world.color.astype(float)
    assert np.ptp(colors[:11], axis=0).max() < 40                       # a team shares its kit
    assert any(len(d.rows) < len(t) for t, d, *_ in rec)             # touching players become one blob


def test_umbrellas_same_colour_different_texture_on_a_shaking_camera():
    env, rec = run("umbrellas", 220, obs_mode="detections")
    assert (env.source.world.color[0] == env.source.world.color[1]).all()
    assert env.source.world.texture_of_group.tolist() == [1, 2]
    offsets = np.array([o for *_, o in rec])
    assert np.ptp(offsets, axis=0).min() >= 2                           # the handheld camera shakes
    assert any((t.visibility < 0.9).any() for t, *_ in rec)          # the trunk hides an umbrella


def test_books_small_books_are_hidden_completely_and_carried_by_the_books_over_them():
    env, rec = run("books", 400, obs_mode="detections")
    vis = np.array([t.visibility for t, *_ in rec])                  # (frames, 4): ids 1, 2 small, 3 large, 4 cover
    centres = np.array([t.boxes[:2, :2] + t.boxes[:2, 2:] / 2 for t, *_ in rec])
    assert vis.shape == (400, 4) and env.source.world.shape_is_rect.all() and not env.source.world.carrier_id[2:].any()
    hidden = vis[:, :2] < 0.05
    assert hidden.sum() >= 30                                         # complete occlusions are common
    for k in range(2):                                                # a hidden book moves with its carrier
        rows = np.flatnonzero(hidden[:, k])
        if len(rows) >= 20:
            assert np.hypot(*(centres[rows[-1], k] - centres[rows[0], k])) > 30
            break
    else:
        pytest.fail("no small book stayed hidden for 20 frames")


def test_skating_camera_follows_fast_skaters():
    env, rec = run("skating", 500)
    offsets = np.array([o for *_, o in rec])
    assert np.ptp(offsets[:, 0]) > 10 and np.abs(np.diff(offsets[:, 0])).max() <= 6   # pans, at most 6 px a frame
    centres = np.array([(t.boxes[:, 0] + t.boxes[:, 2] / 2).mean() for t, *_ in rec])
    inside = (offsets[:, 0] > 0) & (offsets[:, 0] < 640 - 320)       # away from the rink's ends the camera keeps up
    assert inside.sum() > 20 and np.median(np.abs(centres[inside] - 160)) < 10
    assert np.hypot(*env.source.world.vel.T).max() > 3


def test_mot17_like_crowd_enters_by_borders_and_doors_in_dim_light():
    env, rec = run("mot17_like", 150)
    assert len(rec[0][0]) == 21 and env.source.world.births > 2  # 15 walkers and 6 strollers to start with
    assert max(m for *_, m, _ in rec) < 90                             # dim
    assert np.mean([(t.visibility < 1).sum() for t, *_ in rec]) > 0.5   # people occlude each other
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


def walker(ids, path):
    """Truths of one person of height 50 walking through the given feet positions, one per frame."""
    return [Truth(ids=np.array([ids]), boxes=np.array([[x - 10.0, y - 50.0, 20.0, 50.0]], np.float32),
                  visibility=np.ones(1, np.float32), visible_boxes=np.zeros((1, 4), np.float32),
                  depth=np.zeros(1, np.float32), labels=np.ones(1, int), pieces=np.zeros((0, 5), np.float32))
            for x, y in path]


def test_heading_changes_by_hand():
    straight = [(10.0 * k, 0.0) for k in range(11)]
    assert truth_statistics.heading_changes(walker(1, straight)).tolist() == [0.0]
    corner = [(10.0 * k, 0.0) for k in range(6)] + [(50.0, 10.0 * k) for k in range(1, 6)]  # right, then down
    assert truth_statistics.heading_changes(walker(1, corner)) == pytest.approx([90.0])
    still = [(0.0, 0.0)] * 11  # no direction to speak of
    assert len(truth_statistics.heading_changes(walker(1, still))) == 0


def test_mot17_like_has_mot17_scene_statistics():
    truths, _ = truth_statistics.record("mot17_like", seed=0)
    stats = truth_statistics.summary(truths)
    assert len(truths) >= 600
    assert 16 <= stats["people per frame"] <= 28  # MOT17: 21 on average
    assert 14 <= np.mean([len(t) for t in truths[-100:]]) <= 28  # births and exits balance: no crowd builds up
    frames, rate, _ = motion.scored_frames("mot17_like", seed=0)
    people = motion.people(frames, rate)
    assert people["standing"] >= 0.15  # MOT17-02: 0.49, MOT17-09: 0.09; the earlier walkers stood in 1 % of seconds
    assert 0.05 <= people["deviation"] <= 0.15  # a still camera's (MOT17-02 0.054, -09 0.144); moving ones 0.15-0.75


def test_a_variant_is_its_base_with_its_own_keys(tmp_path):
    moving = load("mot17_moving")
    assert moving.render.camera == "walking" and moving.world.size == (2400.0, 540.0)
    assert moving.sensor == load("mot17_like").sensor and moving.groups[0].count == 38
    (tmp_path / "loop.toml").write_text(f'base = "{tmp_path / "loop.toml"}"\n')
    with pytest.raises(ConfigError, match="without a cycle"):
        load(tmp_path / "loop.toml")
