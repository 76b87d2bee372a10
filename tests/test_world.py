"""The pymunk world: motion models, collisions, layers, carrying, births and deaths."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import BOOKS_WITH_DECOY, still, tiny
from mtt_sim.env import NO_TRACKS, TrackingEnv
from mtt_sim.sim.scenario import load
from mtt_sim.sim.spots import SpotGrid
from mtt_sim.sim.world import World


def world(sc, seed=0):
    return World(sc, np.random.default_rng(seed))


def moving(name, x, vx, layer=0):
    g = still(name=name, layer=layer, size=(20.0, 20.0))
    g.update(region=[x, 0.45, x + 0.01, 0.55], speed=abs(vx), heading=0.0 if vx > 0 else 180.0, heading_jitter=0.0,
             speed_jitter=0.0, accel=0.0)
    return g


def test_same_layer_targets_bounce_and_other_layers_pass_through():
    for layers, swapped in (((0, 0), False), ((0, 1), True)):
        w = world(tiny([moving("a", 0.3, 2.0, layers[0]), moving("b", 0.7, -2.0, layers[1])]))
        for _ in range(25):  # they meet after about 15 frames
            w.step()
        assert (w.pos[0, 0] > w.pos[1, 0]) == swapped, layers


def test_walls_keep_targets_inside_the_world():
    w = world(load("dense", {"groups.0.speed": 6.0, "groups.0.count": 50}))
    for _ in range(200):
        w.step()
    assert len(w.ids) == 50
    assert (w.pos >= 0).all() and (w.pos <= w.extent).all()


def test_without_walls_targets_leave_and_die():
    w = world(tiny([moving("a", 0.5, 5.0)]))
    for _ in range(40):
        w.step()
    assert len(w.ids) == 0 and w.finished


def test_carried_target_keeps_its_offset_to_the_carrier_even_against_a_wall():
    # the carrier runs straight into the right wall and is held there; the book it carries must not slide off
    w = world(load(BOOKS_WITH_DECOY, {"groups.1.motion": "cv", "groups.1.heading": 0.0,
                                      "groups.1.heading_jitter": 0.0, "groups.1.speed": 6.0, "groups.1.accel": 0.0}))
    carried = int(np.flatnonzero(w.carrier_id)[0])
    carrier = int(np.flatnonzero(w.ids == w.carrier_id[carried])[0])
    offset = w.pos[carried] - w.pos[carrier]
    right = []
    for _ in range(150):
        w.step()
        right.append(w.pos[carrier][0] + w.size[carrier][0] / 2)
        np.testing.assert_allclose(w.pos[carried] - w.pos[carrier], offset, atol=1e-6)
    assert max(right) > w.extent[0] - 5 > right[-1]  # it reached the wall and bounced off


def test_border_births_enter_inward_with_unique_ids():
    sc = tiny([{**still(count=0), "birth_rate": 0.5, "speed": 2.0, "heading_jitter": 180.0}])
    w = world(sc)
    seen = set()
    for _ in range(100):
        w.step()
        born_now = w.born == w.t
        to_centre = w.extent / 2 - w.pos[born_now]
        assert (np.sum(to_centre * w.vel[born_now], axis=1) > 0).all()
        assert len(set(w.ids.tolist())) == len(w.ids)
        seen |= set(w.ids.tolist())
    assert w.births > 20 and seen == set(range(1, w.next_id)) & seen


def test_exit_door_absorbs_goal_seekers():
    door = {"rect": [180.0, 40.0, 20.0, 20.0], "role": "exit"}
    g = {**still(), "motion": "goal", "speed": 3.0, "region": [0.05, 0.45, 0.1, 0.55]}
    w = world(tiny([g], doors=[door]))
    for _ in range(100):
        w.step()
        if not len(w.ids):
            break
    assert len(w.ids) == 0 and w.t < 100


def test_door_births_and_population_cap():
    door = {"rect": [90.0, 40.0, 20.0, 20.0], "role": "entry", "birth_rate": 5.0}
    w = world(tiny([still(count=0)], doors=[door], world={"max_alive": 7, "max_births": 10}))
    for _ in range(30):
        w.step()
        assert len(w.ids) <= 7
    assert w.births <= 10


def test_standing_targets_shrink_as_they_walk_away():
    g = {**still(size=(20.0, 50.0)), "region": [0.5, 0.9, 0.51, 0.95], "speed": 1.0, "heading": -90.0,
         "heading_jitter": 0.0, "speed_jitter": 0.0}
    w = world(tiny([g], world={"projection": "standing", "far_scale": 0.4}, render={"height": 300}))
    h0 = w.boxes()[0, 3]
    for _ in range(100):
        w.step()
    assert w.boxes()[0, 3] < 0.85 * h0


def test_random_walk_velocity_is_redrawn_each_frame():
    g = {**still(count=30), "motion": "random_walk", "speed": 2.0, "region": [0.1, 0.1, 0.9, 0.9], "size": [2.0, 2.0]}
    w = world(tiny([g], world={"walls": True, "collision": "none"}, render={"width": 600, "height": 600}))
    vels = []
    for _ in range(50):
        w.step()
        vels.append(w.vel.copy())
    v = np.concatenate(vels)
    assert abs(v.std() - 2.0) < 0.2
    lag = np.mean(np.sum(vels[0] * vels[1], axis=1))
    assert abs(lag) < 1.5  # successive velocities are independent


def test_manoeuvring_targets_turn_and_stop():
    g = {**still(count=20), "motion": "manoeuvre", "speed": 2.0, "turn_prob": 0.2, "stop_prob": 0.05,
         "region": [0.1, 0.1, 0.9, 0.9], "size": [2.0, 2.0]}
    w = world(tiny([g], world={"walls": True, "collision": "none"}, render={"width": 600, "height": 600}))
    stopped = 0
    for _ in range(60):
        w.step()
        stopped += int(w.stopped.sum())
    assert stopped > 0 and (np.hypot(*w.vel.T) > 0).any()


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 100), st.floats(0, 100), st.floats(0.5, 15), st.integers(0, 1)), max_size=40),
       st.floats(-10, 110), st.floats(-10, 110), st.floats(0.5, 15), st.integers(0, 1))
def test_spot_grid_answers_as_testing_every_placed_target(placed, x, y, radius, layer):
    grid = SpotGrid(cell=12.0)
    for px, py, half, lay in placed:
        grid.add(lay, np.array([px, py]), half)
    same = np.array([(px, py, half) for px, py, half, lay in placed if lay == layer]).reshape(-1, 3)
    brute = bool((np.hypot(*(same[:, :2] - [x, y]).T) > radius + same[:, 2]).all())
    assert grid.is_free(layer, np.array([x, y]), radius) == brute


def test_placing_targets_costs_linear_work(monkeypatch):
    """At a fixed density, 4x the targets compare 4x the distances (testing every placed target would be 16x)."""
    compared = []
    hypot = np.hypot
    monkeypatch.setattr(np, "hypot", lambda a, b: compared.append(np.size(a)) or hypot(a, b))
    work = []
    for n, side in ((300, 1000.0), (1200, 2000.0)):
        compared.clear()
        world(load("dense", {"groups.0.count": n, "world.size": [side, side]}))
        work.append(sum(compared))
    assert work[1] < 6 * work[0], work


def carry_scene(carry_frames: int):
    """A small still book (layer 0) and a large book (layer 1) sliding right over it at 2 px a frame."""
    small = {**still(size=(20.0, 20.0), name="small"), "region": [0.3, 0.5, 0.301, 0.501]}
    large = {"name": "large", "count": 1, "shape": "rect", "size": [60.0, 60.0], "size_jitter": 0.0, "speed": 2.0,
             "speed_jitter": 0.0, "heading": 0.0, "heading_jitter": 0.0, "accel": 0.0, "layer": 1,
             "region": [0.1, 0.5, 0.101, 0.501]}
    return tiny(groups=[small, large], render={"width": 400, "height": 200}, world={"walls": False, "carry_frames": carry_frames},
                env={"max_steps": 200})


@pytest.mark.parametrize("carry_frames", [0, 30])
def test_a_completely_covered_target_rides_with_its_cover_for_carry_frames_then_is_left(carry_frames):
    env = TrackingEnv(carry_scene(carry_frames))
    env.reset(seed=0)
    start = env.source.world.pos[0].copy()
    path = []
    for _ in range(120):
        env.step(NO_TRACKS)
        path.append(env.source.world.pos[0].copy())
    moved = np.array(path) - start
    if not carry_frames:
        assert np.abs(moved).max() < 1e-9                      # covered, but it stays put
        return
    steps = np.flatnonzero(np.diff(moved[:, 0]) > 1.0)         # frames in which it moved with its cover
    assert len(steps) == carry_frames and np.ptp(np.diff(steps)) == 0   # one run of carry_frames frames
    assert moved[-1, 0] == pytest.approx(2.0 * carry_frames, abs=2.5) and abs(moved[-1, 1]) < 1e-6
    assert env.source.world.carrier_id[0] == 0                        # left, touching again
