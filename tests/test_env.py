"""The Gym face: registration, checker, determinism, vector envs, action validation, episode ends."""

import os
import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import mtt_sim
from helpers import BOOKS_WITH_DECOY, still, tiny
from mtt_sim import ActionError, ConfigError, TrackingEnv
from mtt_sim.env import NO_TRACKS

ENV_IDS = sorted(mtt_sim.env_ids().values())


def echo(obs):
    n = int(obs["num_detections"])
    return {"ids": np.arange(n), "boxes": obs["detections"][:n, :4]}


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_check_env_passes(env_id):
    env = gym.make(env_id)
    check_env(env.unwrapped)  # with its render check: every mode this machine can render


def test_every_scenario_has_one_env_id():
    assert len(ENV_IDS) == len(mtt_sim.available()) >= 8
    assert "mtt_sim/Crossing-v0" in ENV_IDS


def test_the_readme_example_runs():
    env = gym.make("mtt_sim/Crossing-v0", render_mode="rgb_array", config={"sensor": {"clutter_rate": 5}})
    obs, info = env.reset(seed=0)
    assert obs["frame"].shape == (288, 384, 3) and obs["frame"].dtype == np.uint8
    dets = obs["detections"][: obs["num_detections"]]
    assert dets.dtype == np.float32 and dets.shape[1] == 5
    assert (obs["detections"][obs["num_detections"]:] == 0).all()
    obs, reward, terminated, truncated, info = env.step(echo(obs))
    assert type(terminated) is bool and type(truncated) is bool and isinstance(reward, float)
    img = env.render()
    assert img.shape == (288, 384, 3) and not np.array_equal(img, obs["frame"])


def test_render_draws_the_tracks_and_drawings_handed_over_on_the_frame_they_answer():
    """The agent hands its tracks, its tracker's debug() drawings and its name to the env before stepping; render()
    after the step shows them on the frame they answered, in the track's colour, enlarged render_scale times."""
    from mtt_sim.show.overlay import track_color

    env = gym.make("mtt_sim/Crossing-v0", render_mode="rgb_array", render_scale=2)
    obs, _ = env.reset(seed=0)
    bare = env.render()
    assert bare.shape == (576, 768, 3)
    ellipse = {"kind": "ellipse", "center": (100.0, 150.0), "axes": (30.0, 20.0), "angle": 0.0, "id": 7}
    env.unwrapped.remember_tracks([7], [[90.0, 130.0, 20.0, 40.0]], [ellipse], "mine")
    env.step(echo(obs))
    img = env.render()
    colour = np.array(track_color(7))
    assert (np.abs(img[300, 254:262].astype(int) - colour).sum(axis=1) < 60).any()  # the ellipse's right edge (antialiased)
    assert (np.abs(img[260:340, 180].astype(int) - colour).sum(axis=1) < 30).any()  # the box's left side
    assert img.shape == bare.shape and not np.array_equal(img[30:], bare[30:])
    with pytest.raises(ValueError, match="render_scale=0: allowed: an integer from 1 to 8"):
        TrackingEnv("crossing", render_scale=0)


def rollout(env_id, seed, steps=100, **kwargs):
    env = gym.make(env_id, **kwargs)
    obs, _ = env.reset(seed=seed)
    out = []
    for _ in range(steps):
        obs, reward, term, trunc, _ = env.step(echo(obs))
        out.append((obs.get("frame", np.zeros(0)).tobytes(), obs["detections"].tobytes(), reward))
        if term or trunc:
            break
    return out


@pytest.mark.parametrize("env_id", ["mtt_sim/Crossing-v0", "mtt_sim/Mot17Like-v0", "mtt_sim/Umbrellas-v0"])
def test_same_seed_is_byte_identical_and_seeds_differ(env_id):
    a, b = rollout(env_id, 7), rollout(env_id, 7)
    assert a == b and len(a) == 100
    assert rollout(env_id, 8, steps=5) != a[:5]


@pytest.mark.parametrize("key", ["books", "skating"])  # textured targets, a noisy backdrop, a following camera
def test_an_episode_without_frames_never_draws_its_looks_and_they_are_the_same_when_drawn_late(key):
    """The backdrop, the pixel-noise bank and the texture tile are drawn on the first frame: an episode in
    detections mode never pays for them, and drawing them late gives the pixels drawing them at once gives."""
    early, late = TrackingEnv(key), TrackingEnv(key, obs_mode="detections")
    early.reset(seed=3)
    late.reset(seed=3)
    for _ in range(5):
        early.step(NO_TRACKS)
        late.step(NO_TRACKS)
    assert "_looks" not in vars(late.source.renderer) and "_looks" in vars(early.source.renderer)
    np.testing.assert_array_equal(late.source.renderer.render(late.source.world)[0], early.frame)


def test_detections_mode_sees_the_same_world_without_frames():
    env_f = gym.make("mtt_sim/Mot17Like-v0")
    env_d = gym.make("mtt_sim/Mot17Like-v0", obs_mode="detections")
    of, _ = env_f.reset(seed=1)
    od, _ = env_d.reset(seed=1)
    assert "frame" not in od and "frame" not in env_d.observation_space.spaces
    for _ in range(20):
        np.testing.assert_array_equal(of["detections"], od["detections"])
        of = env_f.step(NO_TRACKS)[0]
        od = env_d.step(NO_TRACKS)[0]


@pytest.mark.parametrize("context, steps", [("spawn", 50), ("fork", 5), ("forkserver", 5)])
def test_async_vector_env(context, steps):
    envs = gym.make_vec("mtt_sim/Crossing-v0", num_envs=2, vectorization_mode="async",
                        vector_kwargs={"context": context})
    obs, _ = envs.reset(seed=[0, 1])
    assert obs["frame"].shape == (2, 288, 384, 3)
    assert not np.array_equal(obs["frame"][0], obs["frame"][1])
    for _ in range(steps):
        obs, reward, term, trunc, _ = envs.step(envs.action_space.sample())
    assert reward.shape == (2,)
    envs.close()


def test_reset_info_gives_the_visible_initial_targets():
    env = gym.make("mtt_sim/Books-v0")
    _, info = env.reset(seed=0)
    truth = env.unwrapped.truth
    visible = truth.visibility > 0
    np.testing.assert_array_equal(info["init_ids"], truth.ids[visible])
    np.testing.assert_array_equal(info["init_boxes"], truth.boxes[visible])


@pytest.mark.parametrize("action, pattern", [
    ([1, 2], "action must be a dict with 'ids' and 'boxes'"),
    ({"ids": [1]}, r"action must be a dict .* got dict with keys \['ids'\]"),
    ({"ids": [1, 2], "boxes": [[0, 0, 5, 5]]}, r"unpadded action: 'ids' must have shape \(n,\) and 'boxes' \(n, 4\)"),
    ({"ids": [1], "boxes": [[0, 0, np.nan, 5]]}, r"action\['boxes'\] row 0 is not finite"),
    ({"ids": [1, 2], "boxes": [[0, 0, 5, 5], [0, 0, -1, 5]]}, r"row 1 has a non-positive width or height"),
    ({"ids": [3, 3], "boxes": [[0, 0, 5, 5], [1, 1, 5, 5]]}, r"must be unique within a frame; repeated: \[3\]"),
    ({"ids": [1.5], "boxes": [[0, 0, 5, 5]]}, r"action\['ids'\] must be integers"),
    ({"ids": np.zeros(256, np.int64), "boxes": np.ones((256, 4)), "num_tracks": 999}, r"num_tracks'\] = 999: must be an integer in 0\.\.256"),
    ({"ids": np.zeros(3, np.int64), "boxes": np.ones((3, 4)), "num_tracks": 1}, r"padded action: 'ids' must have shape \(256,\)"),
    ({"ids": [1], "boxes": [[1e39, 0, 5, 5]]}, r"row 0 is not finite as float32: \[1e\+39, 0\.0, 5\.0, 5\.0\]"),
    ({"ids": [1], "boxes": [[0, 0, 1e-50, 5]]}, r"row 0 has a non-positive width or height as float32"),
    ({"ids": [1], "boxes": [[1e30, 0, 5, 5]]}, r"row 0 = .* lies outside the action space: x in \[-384, 768\], y in "
                                                r"\[-288, 576\], w in \(0, 768\], h in \(0, 576\]"),
    ({"ids": [1], "boxes": [[0, 0, 5, 900]]}, r"row 0 = \[0\.0, 0\.0, 5\.0, 900\.0\] lies outside the action space"),
    ({"ids": [-1], "boxes": [[0, 0, 5, 5]]}, r"action\['ids'\] -1 is outside 0\.\.2147483647"),
    ({"ids": [1], "boxes": [["a", "b", "c", "d"]]}, r"action\['boxes'\] must be real numbers"),
])
def test_bad_actions_say_what_is_wrong(action, pattern):
    env = TrackingEnv("crossing")
    env.reset(seed=0)
    with pytest.raises(ActionError, match=pattern):
        env.step(action)


def test_an_empty_action_in_any_form_reports_nothing():
    env = TrackingEnv("crossing")
    env.reset(seed=0)
    for action in ({"ids": [], "boxes": []}, {"ids": np.zeros(0, int), "boxes": np.zeros((0, 4))}, NO_TRACKS):
        frame = env.step(action)[4]["frame"]
        assert frame["tp"] == frame["fp"] == frame["idsw"] == 0 and frame["fn"] == frame["num_gt"] > 0


def test_padded_action_counts_only_num_tracks_rows():
    ids = np.zeros(256, np.int64)
    boxes = np.full((256, 4), np.nan, np.float32)  # rows past num_tracks are ignored, even NaN ones
    ids[0], boxes[0] = 5, (10, 10, 5, 5)
    padded, plain = TrackingEnv("crossing"), TrackingEnv("crossing")
    padded.reset(seed=0)
    plain.reset(seed=0)
    _, reward, _, _, info = padded.step({"ids": ids, "boxes": boxes, "num_tracks": 1})
    _, plain_reward, _, _, plain_info = plain.step({"ids": [5], "boxes": [[10, 10, 5, 5]]})
    assert info["frame"] == plain_info["frame"] and reward == plain_reward  # the same as the one track unpadded
    assert info["frame"]["tp"] + info["frame"]["fp"] == 1


def test_bad_config_and_reset_options():
    with pytest.raises(ConfigError, match=r"sensor\.clutter_rate = -1"):
        gym.make("mtt_sim/Crossing-v0", config={"sensor.clutter_rate": -1})
    env = TrackingEnv("clutter_storm", obs_mode="detections")
    env.reset(seed=0, options={"config": {"sensor.clutter_rate": 0.0, "sensor.pd": 0.0}})
    assert env.detections.rows.shape == (0, 5)
    with pytest.raises(ValueError, match=r"cannot change render\.width"):
        env.reset(options={"config": {"render.width": 100}})
    with pytest.raises(ValueError, match="unknown key"):
        env.reset(options={"seed": 3})
    with pytest.raises(ValueError, match="render_mode='video'"):
        TrackingEnv("crossing", render_mode="video")


def test_terminated_when_everyone_left_and_truncated_at_max_steps():
    g = {**still(), "speed": 4.0, "heading": 0.0, "heading_jitter": 0.0, "speed_jitter": 0.0}
    env = TrackingEnv(tiny([g]))
    env.reset(seed=0)
    for step in range(1, 100):
        _, _, term, trunc, _ = env.step(NO_TRACKS)
        if term:
            break
    assert term is True and trunc is False and step < 40
    with pytest.raises(RuntimeError, match="call reset"):
        env.step(NO_TRACKS)
    env = TrackingEnv("books", config={"env.max_steps": 3})
    env.reset(seed=0)
    flags = [env.step(NO_TRACKS)[3] for _ in range(3)]
    assert flags == [False, False, True]


def test_human_render_without_a_viewer_says_how_to_get_one(monkeypatch):
    for var in ("DISPLAY", "WAYLAND_DISPLAY", "SDL_VIDEODRIVER"):
        monkeypatch.delenv(var, raising=False)
    with pytest.raises(gym.error.DependencyNotInstalled, match=r"pip install 'mtt-sim\[viewer\]', on a machine with a "
                                                                r"display"):
        gym.make("mtt_sim/Crossing-v0", render_mode="human")
    assert gym.make("mtt_sim/Crossing-v0").unwrapped.metadata["render_modes"] == ["rgb_array"]


HUMAN = """
import gymnasium as gym, numpy as np, mtt_sim, pygame
from gymnasium.utils.env_checker import check_env
shown = []
for mode in ("human", "rgb_array"):
    env = gym.make("mtt_sim/Crossing-v0", render_mode=mode)
    check_env(env.unwrapped)  # renders in every mode, "human" included
    env.reset(seed=0)
    env.step({"ids": [1], "boxes": [[10.0, 10.0, 20.0, 30.0]]})  # human: step shows the frame
    shown.append(pygame.surfarray.array3d(pygame.display.get_surface()).swapaxes(0, 1) if mode == "human" else env.render())
    env.close()
print(shown[0].shape, int(np.array_equal(*shown)))
"""


def test_human_render_shows_the_annotated_frame_in_a_pygame_window():
    pytest.importorskip("pygame")
    out = subprocess.run([sys.executable, "-c", HUMAN], capture_output=True, text=True, timeout=300,
                         env={**os.environ, "SDL_VIDEODRIVER": "dummy"})
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["(288,", "384,", "3)", "1"]  # the window shows what rgb_array returns


def test_truth_is_exposed_on_the_unwrapped_env():
    env = gym.make("mtt_sim/Soccer-v0")
    env.reset(seed=0)
    t = env.unwrapped.truth
    assert len(t) == 22 and t.boxes.dtype == np.float32 and len(set(t.ids.tolist())) == 22


def episode(env_id, seed=0, **kwargs):
    env = gym.make(env_id, **kwargs)
    obs, _ = env.reset(seed=seed)
    rewards, frames = [], []
    while True:
        obs, reward, term, trunc, info = env.step(echo(obs))
        rewards.append(reward)
        frames.append(info["frame"])
        if term or trunc:
            return rewards, frames, info


def test_mota_return_over_gt_boxes_is_mota():
    rewards, frames, info = episode("mtt_sim/Crossing-v0", config={"env.max_steps": 120})
    m = info["metrics"]
    assert sum(rewards) / m["num_gt_dets"] == pytest.approx(m["MOTA"], abs=1e-12)
    assert m["num_frames"] == len(rewards) == 120
    assert sum(f["tp"] for f in frames) == m["TP"] and sum(f["idsw"] for f in frames) == m["IDSW"]
    assert {"MOTA", "IDF1", "HOTA", "GOSPA", "MT"} <= set(m)


def test_gospa_and_iou_rewards():
    rewards, _, info = episode("mtt_sim/ClutterStorm-v0", config={"env.max_steps": 30, "scoring.reward_mode": "gospa"})
    assert -np.mean(rewards) == pytest.approx(info["metrics"]["GOSPA"])
    cfg = {"env.max_steps": 30, "scoring.reward_mode": "iou", "scoring.fp_weight": 0.5, "scoring.fn_weight": 2.0}
    rewards, frames, _ = episode("mtt_sim/ClutterStorm-v0", config=cfg)
    for r, f in zip(rewards, frames):
        assert r == pytest.approx(f["similarity_sum"] - 0.5 * f["fp"] - 2.0 * f["fn"])


def test_min_visibility_drops_hidden_targets_from_scoring():
    decoy = {"scenario": BOOKS_WITH_DECOY}
    _, frames, _ = episode("mtt_sim/Books-v0", **decoy, config={"env.max_steps": 5, "scoring.min_visibility": 0.8})
    assert all(f["num_gt"] < 4 for f in frames)  # the large book, 72 % visible under the top book, is not scored
    _, frames, _ = episode("mtt_sim/Books-v0", **decoy, config={"env.max_steps": 5})
    assert all(f["num_gt"] == 4 for f in frames)
