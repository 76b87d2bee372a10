"""The detector models: known answers for merges, fragments, clutter statistics and the ideal case."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from helpers import placed, still, tiny
from mtt_sim import sensor as sensor_mod
from mtt_sim.scenario import SensorConfig, load
from mtt_sim.sensor import CLUTTER, components, detection_probability
from mtt_sim.env import TrackingEnv


def test_ideal_detector_returns_exactly_the_visible_boxes():
    env = TrackingEnv("mot17_like", config={"sensor": {"preset": "ideal", "pd": 1.0, "clutter_rate": 0.0, "box_noise": 0.0,
                                                       "merge_prob": 0.0, "fragment_prob": 0.0, "min_visibility": 0.0}})
    env.reset(seed=3)
    for _ in range(20):
        t, d = env.truth, env.detections
        seen = t.visibility > 0
        whole = seen & ~np.isin(np.arange(len(t)), t.pieces[:, 0].astype(int))
        expected = np.concatenate([t.visible_boxes[whole], t.pieces[:, 1:]])
        got = d.rows[:, :4]
        assert sorted(map(tuple, got.tolist())) == sorted(map(tuple, expected.tolist()))
        assert set(d.sources.tolist()) == set(t.ids[seen].tolist())
        env.step({"ids": [], "boxes": np.zeros((0, 4))})


def test_two_touching_targets_merge_into_one_union_box():
    groups = [still(name="a", layer=0), still(name="b", layer=1)]
    env = placed(tiny(groups, sensor={"merge_prob": 1.0}), [[80.0, 50.0], [110.0, 50.0]])
    rows = env.detections.rows
    assert len(rows) == 1
    np.testing.assert_allclose(rows[0, :4], [60, 30, 70, 40], atol=1)


def test_targets_apart_do_not_merge():
    groups = [still(name="a"), still(name="b")]
    env = placed(tiny(groups, sensor={"merge_prob": 1.0}), [[50.0, 50.0], [150.0, 50.0]])
    assert len(env.detections.rows) == 2


def test_an_occluder_cut_always_gives_fragments():
    pole = {"rect": [98.0, 0.0, 4.0, 100.0]}
    env = placed(tiny([still(shape="rect")], occluders=[pole]), [[100.0, 50.0]])
    rows = env.detections.rows[np.argsort(env.detections.rows[:, 0])]
    np.testing.assert_allclose(rows[:, :4], [[80, 30, 18, 40], [102, 30, 18, 40]])


def test_random_fragmentation_splits_into_two_or_three_boxes_inside_the_target():
    env = placed(tiny([still(shape="rect", size=(80.0, 40.0))], sensor={"fragment_prob": 1.0}), [[100.0, 50.0]])
    rows = env.detections.rows
    assert len(rows) in (2, 3)
    assert (rows[:, 0] >= 60).all() and (rows[:, 0] + rows[:, 2] <= 140 + 1e-4).all()
    assert (rows[:, 2] < 80).all() and np.allclose(rows[:, 3], 40)


def test_clutter_counts_follow_the_poisson_mean():
    sc = tiny(sensor={"clutter_rate": 3.0})
    s = sensor_mod.SyntheticSensor(sc, np.random.default_rng(0))
    env = placed(sc, [[100.0, 50.0]])
    counts = [(s.detect(env.truth, env.labels).sources == CLUTTER).sum() for _ in range(2000)]
    assert abs(np.mean(counts) - 3.0) < 0.15  # standard error 0.039
    assert abs(np.var(counts) - 3.0) < 0.4   # Poisson: variance = mean


def test_confidences_separate_true_from_false_detections_on_average():
    env = TrackingEnv("clutter_storm", obs_mode="detections")
    env.reset(seed=0)
    d = env.detections
    assert d.rows[d.sources > 0, 4].mean() > d.rows[d.sources == CLUTTER, 4].mean() + 0.1
    assert ((d.rows[:, 4] >= 0) & (d.rows[:, 4] <= 1)).all()


def test_detection_probability_rises_with_visibility():
    cfg = SensorConfig(pd=0.9, min_visibility=0.2)
    p = detection_probability(np.linspace(0, 1, 101), cfg)
    assert p[-1] == np.float64(0.9) and (p[:21] == 0).all() and (np.diff(p[20:]) > 0).all()
    assert (detection_probability(np.array([0.3, 1.0]), SensorConfig(pd=1.0, min_visibility=0.2)) == 1).all()


def test_foreground_detector_finds_a_lone_target():
    sc = tiny([still(size=(30.0, 30.0))], sensor={"model": "foreground", "clutter_rate": 0.0},
              render={"background_color": [40, 40, 40]})
    env = placed(sc, [[100.0, 50.0]])
    env.observe()
    rows = env.detections.rows
    assert len(rows) == 1
    np.testing.assert_allclose(rows[0, :4], env.truth.boxes[0], atol=2)


def test_max_detections_keeps_the_most_confident():
    env = TrackingEnv("clutter_storm", config={"sensor.max_detections": 5}, obs_mode="detections")
    obs, _ = env.reset(seed=0)
    assert obs["num_detections"] == 5 and obs["detections"].shape == (5, 5)


@given(st.integers(1, 12), st.lists(st.tuples(st.integers(0, 11), st.integers(0, 11)), max_size=20))
def test_components_match_a_union_find(n, edges):
    edges = [(a % n, b % n) for a, b in edges]
    parent = list(range(n))

    def find(x):
        while parent[x] != x:
            x = parent[x]
        return x

    for a, b in edges:
        parent[find(a)] = find(b)
    i = np.array([a for a, _ in edges], int)
    j = np.array([b for _, b in edges], int)
    got = components(n, i, j)
    for a in range(n):
        for b in range(n):
            assert (got[a] == got[b]) == (find(a) == find(b))


def test_load_uses_shipped_preset_values():
    assert load("dense").sensor.pd == 0.93
