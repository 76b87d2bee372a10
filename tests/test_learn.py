"""Track management learned from the reward: the candidates, the TrackManagement env, the policy search and the
`learned` tracker."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from helpers import write_sequence
from mtt_sim.trackers.learned import load_policy, save_policy
from mtt_sim.trackers.parts.management import FEATURES, SORT_RULES, Candidates, decisions

import mtt_sim  # noqa: F401  (registers the env ids)
from mtt_sim import trackers
from mtt_sim.cli import main
from mtt_sim.env import TrackingEnv
from mtt_sim.learn.management_env import DECISION_COLOURS
from mtt_sim.learn.policy_search import learn_policy

HARD = {"sensor.preset": "dpm", "env.max_steps": 60}  # a detector that misses for long: SORT's max_age=1 loses ids
# (seeds 0 to 2 of this search all gain over SORT's rules here: 0.560 -> 0.591, 0.588, 0.564)


def test_sort_rules_as_a_linear_policy_are_sort_box_for_box():
    env = TrackingEnv("crossing", config={"sensor.clutter_rate": 2.0, "sensor.pd": 0.8, "env.max_steps": 150})
    sort, learned = trackers.make("sort"), trackers.make("learned:policy=sort_rules")
    obs, info = env.reset(seed=4)
    sort.reset(info)
    learned.reset(info)
    frames = 0
    while True:
        a, b = sort.update(obs), learned.update(obs)
        assert np.array_equal(a.ids, b.ids) and np.array_equal(a.boxes, b.boxes)
        frames += len(a)
        obs, _, terminated, truncated, _ = env.step(a.to_action())
        if terminated or truncated:
            break
    assert frames > 100  # tracks were reported, so the comparison compared something


def test_candidates_keep_an_id_while_kept_and_start_afresh_when_dropped():
    det = np.array([[10.0, 10.0, 20.0, 40.0, 0.9]])
    kept, dropped = Candidates((100, 80)), Candidates((100, 80))
    for frame in range(3):
        features = kept.propose(det)
        assert features.shape == (1, len(FEATURES)) and features[0, FEATURES.index("matched")] == 1
        assert kept.decide([True], [True])[0].tolist() == [1]
        dropped.propose(det)
        assert dropped.decide([True], [False])[0].tolist() == [frame + 1]
    assert kept.propose(np.zeros((0, 5)))[0, FEATURES.index("misses")] == pytest.approx(0.1)  # one miss: 1 / 10
    assert kept.decide([False], [True])[0].size == 0


def test_bytetrack_candidates_take_low_confidence_detections_only_while_tracked():
    """ByteTrack's association: a detection under track_thresh (0.5) starts nothing, but continues a candidate matched
    the frame before (its second round); after a missed frame it no longer does."""
    high, low = np.array([[10.0, 10.0, 20.0, 40.0, 0.9]]), np.array([[11.0, 10.0, 20.0, 40.0, 0.3]])
    c = Candidates((100, 80), base="bytetrack")
    assert len(c.propose(low)) == 0
    c.propose(high)
    features = c.propose(low)
    assert features[0, FEATURES.index("matched")] == 1 and features[0, FEATURES.index("confidence")] == 0.3
    assert features[0, FEATURES.index("streak")] == pytest.approx(0.1)  # one match after the birth
    assert c.decide([True], [True])[0].tolist() == [1]
    c.propose(np.zeros((0, 5)))
    c.decide([False], [True])
    assert c.propose(low)[0, FEATURES.index("matched")] == 0  # missed last frame: not in the second round
    assert c.propose(high)[0, FEATURES.index("matched")] == 1  # a high detection finds it again (first round)


def test_learned_tracker_runs_on_either_base_through_gym():
    for base in ("sort", "bytetrack"):
        m = trackers.make(f"learned:base={base}")
        env = gym.make("mtt_sim/Mot17Like-v0", config={"env.max_steps": 40})
        obs, info = env.reset(seed=0)
        m.reset(info)
        while True:
            obs, _, terminated, truncated, info = env.step(m.update(obs).to_action(env.action_space))
            if terminated or truncated:
                break
        assert info["metrics"]["MOTA"] > 0.5, base


def test_sort_rules_decide_as_sort_does():
    def features(matched, streak, misses, first):
        row = np.zeros(len(FEATURES), np.float32)
        row[[FEATURES.index(k) for k in ("matched", "streak", "misses", "first_frames")]] = matched, streak / 10, \
            misses / 10, first
        return row[None]

    assert decisions(SORT_RULES, features(1, 3, 0, 0))[0].item()           # matched with a streak of 3: report
    assert not decisions(SORT_RULES, features(1, 2, 0, 0))[0].item()       # streak of 2: not yet
    assert decisions(SORT_RULES, features(1, 0, 0, 1))[0].item()           # the first frames: at once
    assert not decisions(SORT_RULES, features(0, 9, 1, 0))[0].item()       # missed: not reported
    assert decisions(SORT_RULES, features(0, 0, 1, 0))[1].item()           # one miss: kept (max_age 1)
    assert not decisions(SORT_RULES, features(0, 0, 2, 0))[1].item()       # two: dropped


def _sort_agent(obs) -> np.ndarray:
    n = int(obs["mask"].sum())
    action = np.zeros((len(obs["mask"]), 2), np.int8)
    action[:n] = np.stack(decisions(SORT_RULES, obs["features"][:n]), axis=1)
    return action


def test_management_env_with_sort_rules_returns_sorts_mota():
    env = gym.make("mtt_sim/TrackManagement-v0", scenario="crossing", config={"env.max_steps": 120})
    obs, info = env.reset(seed=2)
    total = 0.0
    while True:
        obs, reward, terminated, truncated, info = env.step(_sort_agent(obs))
        total += reward
        if terminated or truncated:
            break
    from mtt_sim.lab.experiment import run_episode

    sort = run_episode("crossing", "sort", seed=2, config={"env.max_steps": 120})["metrics"]
    assert info["metrics"]["MOTA"] == sort["MOTA"] and info["metrics"]["HOTA"] == sort["HOTA"]
    assert total / sort["num_gt_dets"] == pytest.approx(sort["MOTA"])


@pytest.mark.parametrize("base", ["sort", "bytetrack"])
def test_management_env_passes_the_checker_and_runs_vectorised(base):
    env = gym.make("mtt_sim/TrackManagement-v0", scenario="crossing", render_mode="rgb_array",
                   config={"env.max_steps": 30}, base=base)
    check_env(env.unwrapped)
    envs = gym.make_vec("mtt_sim/TrackManagement-v0", num_envs=2, scenario="crossing",
                        config={"env.max_steps": 20}, base=base)
    obs, _ = envs.reset(seed=[0, 1])
    assert obs["features"].shape == (2, 64, len(FEATURES))
    obs, reward, *_ = envs.step(np.ones((2, 128), np.int8))
    assert reward.shape == (2,)


def test_management_env_renders_each_decision_in_its_colour():
    env = gym.make("mtt_sim/TrackManagement-v0", scenario="crossing", render_mode="rgb_array",
                   config={"env.max_steps": 30}).unwrapped
    obs, _ = env.reset(seed=0)
    assert obs["mask"].sum() == 2
    action = np.zeros((64, 2), np.int8)
    action[0] = 0, 1  # the first candidate kept unreported, the second dropped
    env.step(action)
    pixels = env.render().reshape(-1, 1, 3).astype(int)
    near = np.abs(pixels - np.array([DECISION_COLOURS["keep"], DECISION_COLOURS["drop"]])).max(axis=2) <= 16
    assert near.sum(axis=0).min() >= 20  # both outlines drawn (anti-aliased, so near the colour)


def test_management_env_takes_a_sequence_folder_and_its_twin(tmp_path):
    gt = [(f, 1, 10.0 + 2 * f, 10.0, 12.0, 30.0, 1, 1, 1.0) for f in range(1, 11)]
    det = [(f, 10.0 + 2 * f, 10.0, 12.0, 30.0, 0.9) for f in range(1, 11)]
    folder = write_sequence(tmp_path / "seq", det=det, gt=gt)
    for config in (None, {"sensor.model": "synthetic"}):
        env = gym.make("mtt_sim/TrackManagement-v0", scenario=str(folder), config=config)
        obs, _ = env.reset(seed=0)
        done = False
        while not done:
            obs, _, terminated, truncated, info = env.step(_sort_agent(obs))
            done = terminated or truncated
        assert 0 <= info["metrics"]["HOTA"] <= 1


def test_management_env_rejects_bad_actions_and_arguments():
    env = gym.make("mtt_sim/TrackManagement-v0", scenario="crossing").unwrapped
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"action shape \(3, 2\): expected \(128,\) or \(64, 2\)"):
        env.step(np.ones((3, 2), np.int8))
    with pytest.raises(ValueError, match="expected 0 or 1"):
        env.step(np.full((64, 2), 2))
    with pytest.raises(ValueError, match="base='deepsort': allowed: 'sort', 'bytetrack'"):
        gym.make("mtt_sim/TrackManagement-v0", base="deepsort")
    with pytest.raises(ValueError, match="max_candidates=0"):
        gym.make("mtt_sim/TrackManagement-v0", max_candidates=0)


def test_learning_improves_on_sorts_rules_and_one_seed_gives_one_policy():
    learning = learn_policy(["mot17_like"], seeds=[1000], generations=2, population=4, config=HARD, seed=1)
    assert learning.fitness > learning.start_fitness  # strictly better than SORT's rules on the training episodes
    assert learning.best_so_far == sorted(learning.best_so_far) and len(learning.generation_mean) == 2
    again = learn_policy(["mot17_like"], seeds=[1000], generations=2, population=4, config=HARD, seed=1, workers=2)
    assert np.array_equal(again.weights, learning.weights) and again.fitness == learning.fitness


def test_learn_policy_command_writes_a_policy_the_learned_tracker_runs(tmp_path, capsys):
    out = tmp_path / "p.npz"
    assert main(["learn-policy", "--on", "crossing", "--seeds", "1000-1000", "--frames", "40", "--generations", "1",
                 "--population", "4", "--out", str(out), "--config", "sensor.preset=dpm"]) == 0
    assert "SORT's rules" in capsys.readouterr().out
    assert load_policy(out).shape == SORT_RULES.shape
    tracker = trackers.make(f"learned:policy={out}")
    assert tracker.weights.shape == SORT_RULES.shape
    assert main(["learn-policy", "--on", "crossing", "--metrics", "MOTA,IDSW", "--out", str(tmp_path / "q.npz")]) == 2
    assert "IDSW: the fitness is a mean of scores where higher is better" in capsys.readouterr().err


def test_a_malformed_policy_file_is_named(tmp_path):
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a policy")
    with pytest.raises(ValueError, match=f"policy file {bad}: not a policy"):
        trackers.make(f"learned:policy={bad}")
    wrong = tmp_path / "wrong.npz"
    save_policy(wrong, np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"expected finite weights \(2, 15\)"):
        load_policy(wrong)


def test_the_shipped_policy_loads_and_says_what_it_was_trained_on():
    from mtt_sim.trackers.learned import SHIPPED_POLICY

    with np.load(SHIPPED_POLICY) as data:
        assert "mot17_like" in str(data["trained_on"]) and "MOT15" not in str(data["trained_on"])
    assert not np.array_equal(trackers.make("learned").weights, SORT_RULES)
