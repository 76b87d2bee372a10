"""The env with Gymnasium's own wrappers and vector API, as an RL user would combine them."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.wrappers import FlattenObservation, RecordEpisodeStatistics, RecordVideo, TimeLimit

import mtt_sim  # noqa: F401  (registers the env ids)

NO_TRACKS = {"ids": np.zeros(0, np.int64), "boxes": np.zeros((0, 4))}


def echo_policy(obs, action_space):
    """A heuristic policy: report this frame's detections as tracks numbered 1..n."""
    n = int(obs["num_detections"])
    action = {k: np.zeros(v.shape, v.dtype) for k, v in action_space.spaces.items()}
    action["ids"][:n] = np.arange(1, n + 1)
    action["boxes"][:n] = obs["detections"][:n, :4]
    action["num_tracks"] = np.int64(n)
    return action


def test_record_video_writes_an_mp4(tmp_path):
    pytest.importorskip("moviepy", reason="RecordVideo needs moviepy (in the [test] extra)")
    env = gym.make("mtt_sim/Books-v0", render_mode="rgb_array", config={"env.max_steps": 12})
    env = RecordVideo(env, str(tmp_path / "videos"), episode_trigger=lambda _: True, disable_logger=True)
    env.reset(seed=0)
    done = False
    while not done:
        _, _, term, trunc, _ = env.step(NO_TRACKS)
        done = term or trunc
    env.close()
    videos = list((tmp_path / "videos").glob("*.mp4"))
    assert len(videos) == 1 and videos[0].stat().st_size > 1000


def test_record_episode_statistics_and_time_limit():
    env = TimeLimit(gym.make("mtt_sim/ClutterStorm-v0", obs_mode="detections"), max_episode_steps=7)
    env = RecordEpisodeStatistics(env)
    obs, _ = env.reset(seed=0)
    rewards, steps = [], 0
    while True:
        obs, reward, term, trunc, info = env.step(echo_policy(obs, env.action_space))
        rewards.append(reward)
        steps += 1
        if term or trunc:
            break
    assert steps == 7 and trunc and not term
    assert info["episode"]["l"] == 7 and info["episode"]["r"] == pytest.approx(sum(rewards))


def test_the_episode_metrics_whatever_ends_the_episode():
    """The env's own limit (the scenario's env.max_steps) gives info["metrics"] on the last step; when a TimeLimit
    ends the episode first, the same summary is env.unwrapped.metrics.summary()."""
    ended = {}
    for how, env in (("own", gym.make("mtt_sim/ClutterStorm-v0", obs_mode="detections", config={"env.max_steps": 7})),
                     ("time_limit", gym.make("mtt_sim/ClutterStorm-v0", obs_mode="detections", max_episode_steps=7))):
        obs, _ = env.reset(seed=0)
        while True:
            obs, _, term, trunc, info = env.step(echo_policy(obs, env.action_space))
            if term or trunc:
                break
        assert trunc and env.unwrapped.metrics.summary()["num_frames"] == 7
        ended[how] = info.get("metrics"), env.unwrapped.metrics.summary()
    assert ended["own"][0] == ended["own"][1] == ended["time_limit"][1] and ended["time_limit"][0] is None


def test_flatten_observation_gives_a_vector_in_its_space():
    env = FlattenObservation(gym.make("mtt_sim/ClutterStorm-v0", obs_mode="detections"))
    obs, _ = env.reset(seed=0)
    assert obs.ndim == 1 and env.observation_space.contains(obs)
    obs, *_ = env.step(NO_TRACKS)
    assert env.observation_space.contains(obs)


def episode_return(env, seed, steps):
    obs, _ = env.reset(seed=seed)
    total = 0.0
    for _ in range(steps):
        obs, reward, *_ = env.step(echo_policy(obs, env.action_space))
        total += reward
    return total


def test_a_policy_over_a_vector_env_returns_what_single_envs_return():
    kwargs = {"obs_mode": "detections", "config": {"env.max_steps": 10}}
    envs = gym.make_vec("mtt_sim/ClutterStorm-v0", num_envs=2, vectorization_mode="sync", **kwargs)
    obs, _ = envs.reset(seed=0)                  # sub-envs seeded 0 and 1
    single = envs.single_action_space
    total = np.zeros(2)
    for _ in range(10):
        actions = [echo_policy({k: v[i] for k, v in obs.items()}, single) for i in range(2)]
        obs, reward, term, trunc, _ = envs.step({k: np.stack([a[k] for a in actions]) for k in single.spaces})
        total += reward
    envs.close()
    env = gym.make("mtt_sim/ClutterStorm-v0", **kwargs)
    assert trunc.all() and total.tolist() == [episode_return(env, 0, 10), episode_return(env, 1, 10)]
    assert (total != 0).all()
