"""A camera going forward over the ground (render.camera_forward): the flow by hand, in the world and in the env."""

import numpy as np
import pytest

from helpers import tiny
from mtt_sim.sim import forward
from mtt_sim.sim.scenario import ConfigError, load
from mtt_sim.sim.world import World
from mtt_sim.sim2real import motion


def test_the_flow_by_hand():
    # far_scale 0.5 over a world 100 high: the horizon is at row -100; a step of 0.1 at the bottom row
    pos = np.array([[50.0, 100.0], [90.0, 100.0], [10.0, 0.0]])
    out = forward.flow(pos, (100.0, 100.0), 0.5, 0.1)
    bottom, top = 1 / (1 - 0.1), 1 / (1 - 0.1 * 0.5)  # depth factors 1 and 0.5
    assert out[0] == pytest.approx([50.0, -100.0 + 200.0 * bottom])  # on the middle column: straight down
    assert out[1] == pytest.approx([50.0 + 40.0 * bottom, -100.0 + 200.0 * bottom])
    assert out[2] == pytest.approx([50.0 - 40.0 * top, -100.0 + 100.0 * top])  # farther: slower
    assert forward.flow(pos, (100.0, 100.0), 0.5, 0.0) == pytest.approx(pos)


def standing(forward_rate: float, far: float = 0.5):
    groups = [{"count": 4, "speed": 0.0, "accel": 0.0, "size_jitter": 0.0, "size": [10.0, 30.0],
               "region": [0.2, 0.3, 0.8, 0.7]}]
    return tiny(groups, world={"projection": "standing", "far_scale": far, "collision": "none"},
                render={"camera_forward": forward_rate})


def test_people_grow_as_far_as_they_slide_out_from_the_focus():
    w = World(standing(2.0), np.random.default_rng(0))
    before, pos = w.boxes(), w.pos.copy()
    w.step()
    grow = w.boxes()[:, 3] / before[:, 3]
    assert (grow > 1).all()
    focus = np.array([100.0, -0.5 * 100 / 0.5])  # the middle column, the horizon's row (far_scale 0.5, 100 high)
    assert (w.pos - focus) == pytest.approx((pos - focus) * grow[:, None])  # the drawn size and the feet agree
    still = World(standing(0.0), np.random.default_rng(0))
    still.step()
    assert still.pos == pytest.approx(pos)  # without it nobody moves


def test_a_horizon_inside_the_world_draws_nobody_below_the_smallest_size():
    w = World(standing(0.0, far=-1.0), np.random.default_rng(0))  # horizon at mid-height
    w.place(np.array([[50.0, 10.0], [60.0, 40.0], [70.0, 75.0], [80.0, 99.0]]))
    heights = w.boxes()[:, 3]
    assert heights[:2] == pytest.approx([30.0 * 0.02] * 2)  # above the horizon: MIN_DEPTH
    assert heights[2:] == pytest.approx(30.0 * (-1.0 + 2.0 * np.array([0.75, 0.99])))


def test_a_topdown_world_or_a_flat_ground_refuses_it():
    for table in ({"projection": "topdown"}, {"projection": "standing", "far_scale": 1.0}):
        with pytest.raises(ConfigError, match="render.camera_forward = 0.5 needs a ground in perspective"):
            load("mot17_like", {"render.camera_forward": 0.5, **{f"world.{k}": v for k, v in table.items()}})


def test_people_seen_from_a_camera_going_forward_leave_the_view_sooner():
    def in_view(config):
        frames, rate, _ = motion.scored_frames("mot17_like", config, steps=150)
        return motion.people(frames, rate)["time in view"]

    assert in_view({"render.camera_forward": 0.6}) < 0.5 * in_view({})


def test_the_forward_street_for_the_policy_keeps_a_crowd_that_comes_and_goes():
    from helpers import EXPERIMENTS

    frames, rate, _ = motion.scored_frames(str(EXPERIMENTS / "forward_street.toml"), steps=150)
    assert rate == 14.0
    assert 1.0 < motion.people(frames, rate)["time in view"] < 3.0  # people pass within seconds
    assert np.mean([len(ids) for ids, _ in frames[-50:]]) >= 3  # and others come into view


def test_the_cameras_companions_keep_their_place_while_the_ground_flows_out():
    overrides = {"render.camera_forward": 0.6, "world.far_scale": -0.5, "walk.stop_rate": 0.0}
    plain = World(load("mot17_like", overrides), np.random.default_rng(3))
    w = World(load("mot17_like", {**overrides, "render.camera_companions": 2}), np.random.default_rng(3))
    assert len(w.ids) == len(plain.ids) + 2 and w.pos[:-2] == pytest.approx(plain.pos)  # added, the rest as drawn
    ids, start = w.ids[w.companion], w.pos[w.companion].copy()
    assert start[:, 1] == pytest.approx(start[0, 1]) and start[:, 0].mean() == pytest.approx(w.extent[0] / 2)
    width = w.boxes()[w.companion][:, 2]
    assert np.diff(start[:, 0])[0] > width.mean() * 0.9  # abreast, a body width apart, about the middle column
    for _ in range(100):
        w.step()
    still_there = np.isin(w.ids, ids)
    assert still_there.sum() == 2 and w.stopped[still_there].all()  # they stand, and nobody flows them out
    assert np.abs(w.pos[still_there] - start).max() < 0.1 * w.extent[1]  # a sway, not the ground's flow
    frames, rate, _ = motion.scored_frames("mot17_like", {**overrides, "render.camera_companions": 2}, steps=150)
    alone, _, _ = motion.scored_frames("mot17_like", overrides, steps=150)
    assert motion.people(frames, rate)["standing"] > motion.people(alone, rate)["standing"] + 0.05


def test_companions_need_a_camera_going_forward():
    with pytest.raises(ConfigError, match="render.camera_companions = 2: people walk with a camera going forward"):
        load("mot17_like", {"render.camera_companions": 2})
