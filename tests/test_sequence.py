"""Recorded MOTChallenge sequences through the Gym API: reading, frames, TrackEval's scoring rules, fallbacks, errors."""

import json

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import mtt_sim
from mtt_sim import trackers
from helpers import write_sequence
from mtt_sim import TrackingEnv, cli
from mtt_sim.lab import experiment
from mtt_sim.metrics import PRINTED
from mtt_sim.real import motchallenge
from mtt_sim.real.sequence import Recording

A, B, C, D = (0.0, 0.0, 10.0, 20.0), (30.0, 0.0, 10.0, 20.0), (60.0, 0.0, 10.0, 20.0), (0.0, 40.0, 20.0, 10.0)
# frame 1: a pedestrian (A), a static person (B, a distractor), a pedestrian marked not to be scored (C), a car (D)
GT = [(1, 1, *A, 1, 1, 1.0), (1, 2, *B, 1, 7, 0.8), (1, 3, *C, 0, 1, 0.2), (1, 4, *D, 0, 3, 1.0)]
TRACKS = {10: A, 11: B, 12: C, 13: D, 14: (80.0, 60.0, 10.0, 10.0), 15: (33.0, 10.0, 10.0, 20.0)}


def step_once(env, tracks):
    env.reset(seed=0)
    ids = np.array(list(tracks))
    return env.step({"ids": ids, "boxes": np.array([tracks[i] for i in ids])})[4]["frame"]


@pytest.mark.parametrize("benchmark, tp, fp, fn", [
    ("MOT17", 1, 4, 0),  # 11 matches the static person: removed; 15 overlaps it by IoU 0.33 < 0.5: kept, a FP;
                         # 12 (zero-marked pedestrian) and 13 (car) are not distractors: kept, FPs; 14 matches nothing
    ("MOT15", 2, 4, 0),  # no classes: the static person is scored (TP for 11); rows marked 0 are not scored
])
def test_ground_truth_is_scored_as_trackeval_scores_the_benchmark(tmp_path, benchmark, tp, fp, fn):
    folder = write_sequence(tmp_path / "seq", det=[(1, *A, 0.9)], gt=GT)
    frame = step_once(TrackingEnv(folder, benchmark=benchmark), TRACKS)
    assert (frame["tp"], frame["fp"], frame["fn"], frame["num_gt"]) == (tp, fp, fn, tp + fn)


def test_the_benchmark_is_guessed_from_the_name_and_the_columns(tmp_path):
    assert Recording(write_sequence(tmp_path / "a", gt=GT)).benchmark == "MOT17"  # gt.txt with classes
    mot15 = [(1, 1, *A, 1, -1, -1, -1)]  # MOT15: world coordinates where MOT17 has class and visibility
    assert Recording(write_sequence(tmp_path / "b", gt=mot15)).benchmark == "MOT15"
    assert Recording(write_sequence(tmp_path / "MOT20-01", gt=GT)).benchmark == "MOT20"
    with pytest.raises(ValueError, match="row 1 has class -1, not one of MOT20's classes 1..13"):
        Recording(write_sequence(tmp_path / "MOT20-02", gt=mot15))
    with pytest.raises(mtt_sim.ConfigError, match="benchmark='MOT18': allowed values: 'MOT15', 'MOT16'"):
        Recording(tmp_path / "a", benchmark="MOT18")


def test_detections_are_given_as_written_and_frames_one_at_a_time(tmp_path):
    det = [(1, 10.25, -3.5, 20.0, 40.0, 3.2), (1, 50.0, 5.0, 8.0, 16.0, -0.75), (2, 11.0, 0.5, 20.0, 40.0, 0.1)]
    folder = write_sequence(tmp_path / "seq", det=det, gt=[(1, 1, *A, 1, 1, 1.0)], images=True, length=3)
    env = gym.make("mtt_sim/Replay-v0", sequence=str(folder))
    obs, info = env.reset(seed=0)
    assert info["image_size"] == (100, 80) and info["frame_rate"] == 10.0 and info["length"] == 3
    assert obs["detections"].dtype == np.float64 and int(obs["num_detections"]) == 2
    np.testing.assert_array_equal(obs["detections"][:2], np.array(det)[:2, 1:])  # raw confidences 3.2 and -0.75 too
    assert env.observation_space.contains(obs) and (obs["frame"] == 10).all()
    seen = [obs["frame"][0, 0, 0]]
    while True:
        obs, reward, term, trunc, info = env.step({"ids": [], "boxes": []})
        if term or trunc:
            break
        seen.append(obs["frame"][0, 0, 0])
    assert seen == [10, 20, 30] and term and not trunc and info["metrics"]["num_frames"] == 3


def test_a_detections_only_folder_has_no_frames_and_says_so(tmp_path):
    folder = write_sequence(tmp_path / "seq", det=[(1, *A, 0.9)], gt=GT)
    obs, _ = TrackingEnv(folder).reset(seed=0)
    assert "frame" not in obs
    with pytest.raises(mtt_sim.ConfigError, match="has no img1/ folder of frames; use obs_mode='detections'"):
        TrackingEnv(folder, obs_mode="frame+detections")
    with pytest.raises(mtt_sim.ConfigError, match="no img1/ folder"):
        experiment.run_episode(str(folder), "pf")
    with pytest.raises(mtt_sim.ConfigError, match="takes only env.\\*, scoring.\\* and sensor.\\* overrides, not world"):
        TrackingEnv(folder, config={"world.walls": True})
    with pytest.raises(mtt_sim.ConfigError, match="sensor.pd applies to the synthetic detector; add sensor.model"):
        TrackingEnv(folder, config={"sensor.pd": 0.5})
    with pytest.raises(mtt_sim.ConfigError, match="'foreground' needs frames the simulator rendered"):
        TrackingEnv(folder, config={"sensor.model": "foreground"})
    with pytest.raises(mtt_sim.ConfigError, match="'recorded' replays a sequence folder"):
        TrackingEnv("crossing", config={"sensor.model": "recorded"})


def test_without_ground_truth_the_env_runs_unscored_and_says_so(tmp_path):
    folder = write_sequence(tmp_path / "seq", det=[(1, *A, 0.9), (2, *A, 0.9)])
    with pytest.warns(UserWarning, match="no gt/gt.txt, so this env runs unscored"):
        env = TrackingEnv(folder)
    env.reset(seed=0)
    rewards, info = [], {}
    for _ in range(2):
        _, reward, term, trunc, info = env.step({"ids": [1], "boxes": [A]})
        rewards.append(reward)
    assert rewards == [0.0, 0.0] and term and "metrics" not in info
    with pytest.warns(UserWarning, match="runs unscored"):
        assert experiment.run_episode(str(folder), "sort")["metrics"] is None


def test_a_short_seq_length_is_an_error_not_a_cut(tmp_path):
    folder = write_sequence(tmp_path / "seq", det=[(1, *A, 0.9), (5, *A, 0.9)], length=3)
    with pytest.raises(ValueError, match=r"det/det.txt: row 2 has frame 5, outside the sequence's 1..3 \(seqLength\)"):
        Recording(folder)
    (folder / "seqinfo.ini").write_text("[Sequence]\nseqLength=many\n")
    with pytest.raises(mtt_sim.ConfigError, match="seqLength = 'many': expected a positive number"):
        Recording(folder)


def test_without_seqinfo_size_and_length_come_from_the_frames_then_the_data(tmp_path):
    with_images = write_sequence(tmp_path / "a", det=[(2, *A, 0.9)], size=(64, 48), images=True, length=4, seqinfo=False)
    info = Recording(with_images).info
    assert (info.width, info.height, info.length, info.frame_rate, info.name) == (64, 48, 4, 30.0, "a")
    data_only = write_sequence(tmp_path / "b", det=[(7, 10.0, 10.0, 50.5, 30.0, 0.9)], gt=[(3, 1, *D, 1, 1, 1.0)],
                               seqinfo=False)
    info = Recording(data_only).info
    assert (info.width, info.height, info.length) == (61, 50, 7)  # det reaches x 60.5, gt y 50


def test_env_metrics_equal_the_written_results_file_scored(tmp_path, capsys):
    rng = np.random.default_rng(0)
    pos = rng.uniform(0, 60, (4, 2))
    gt, det = [], []
    for f in range(1, 31):
        pos += rng.normal(0, 1, pos.shape)
        for i, (x, y) in enumerate(pos):
            gt.append((f, i + 1, float(x), float(y), 12.0, 24.0, 1, [1, 1, 7, 1][i], 1.0))
            if rng.random() < 0.85:
                det.append((f, *(float(v) for v in (x, y) + rng.normal(0, 1.5, 2)), 12.0, 24.0, float(rng.random())))
    folder = write_sequence(tmp_path / "MOT17-99", det=det, gt=gt, size=(100, 100))
    out = tmp_path / "sort.txt"
    assert cli.main(["run", str(folder), "--tracker", "sort", "--results", str(out), "--json"]) == 0
    in_env = json.loads(capsys.readouterr().out)
    assert cli.main(["eval", "--gt", str(folder), "--results", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == {k: v for k, v in in_env.items() if k in PRINTED}
    assert motchallenge.evaluate_results(folder, out, benchmark="MOT17") == experiment.run_episode(
        str(folder), "sort")["metrics"]


def test_bench_runs_sequence_folders_and_writes_results_files(tmp_path, capsys):
    a = write_sequence(tmp_path / "SEQ-A", det=[(f, 10.0 + f, 10.0, 10.0, 20.0, 0.9) for f in range(1, 9)],
                       gt=[(f, 1, 10.0 + f, 10.0, 10.0, 20.0, 1, 1, 1.0) for f in range(1, 9)])
    b = write_sequence(tmp_path / "SEQ-B", det=[(f, 50.0, 10.0 + f, 10.0, 20.0, 0.9) for f in range(1, 6)],
                       gt=[(f, 1, 50.0, 10.0 + f, 10.0, 20.0, 1, 1, 1.0) for f in range(1, 6)])
    results = tmp_path / "results"
    assert cli.main(["bench", "--scenarios", f"{a},{b}", "--trackers", "sort,iou", "--seeds", "1",
                     "--results-dir", str(results)]) == 0
    assert sorted(p.relative_to(results).as_posix() for p in results.rglob("*.txt")) == [
        "iou/SEQ-A.txt", "iou/SEQ-B.txt", "sort/SEQ-A.txt", "sort/SEQ-B.txt"]
    assert "| sort | 1.000 | 1.000 |" in capsys.readouterr().out


def test_replay_passes_check_env(tmp_path):
    folder = write_sequence(tmp_path / "seq", det=[(1, *A, 0.9), (2, *B, 0.5)], gt=GT, images=True, length=2)
    check_env(gym.make("mtt_sim/Replay-v0", sequence=str(folder)).unwrapped)
    with pytest.raises(ValueError, match="mtt_sim/Replay-v0 needs sequence="):
        gym.make("mtt_sim/Replay-v0")
    with pytest.raises(mtt_sim.ConfigError, match="not a MOTChallenge sequence folder"):
        gym.make("mtt_sim/Replay-v0", sequence=str(tmp_path))


def test_a_hand_initialised_tracker_starts_from_the_scored_first_frame(tmp_path):
    folder = write_sequence(tmp_path / "seq", det=[(1, *A, 0.9)], gt=GT, images=True, length=2)
    _, info = TrackingEnv(folder).reset(seed=0)
    assert info["init_ids"].tolist() == [1] and info["init_boxes"].tolist() == [list(A)]
    assert trackers.make("ipf").reset(info) is None


def test_a_binary_ground_truth_file_is_named_with_what_was_expected(tmp_path):
    folder = write_sequence(tmp_path / "seq", det=[(1, 10.0, 10.0, 5.0, 10.0, 0.9)], gt=[])
    (folder / "gt" / "gt.txt").write_bytes(b"\xeb\x00\xff binary")
    with pytest.raises(ValueError, match=r"gt\.txt: not a text file \('utf-8' codec can't decode byte 0xeb.*expected "
                                         r"comma-separated MOTChallenge rows"):
        Recording(folder)


def test_a_detection_with_a_negative_width_names_the_file_row_and_frame(tmp_path):
    folder = write_sequence(tmp_path / "seq", det=[(1, 10.0, 10.0, 5.0, 10.0, 0.9), (2, 10.0, 10.0, -5.0, 10.0, 0.9)])
    with pytest.raises(ValueError, match=r"det\.txt: row 2 \(frame 2\) has width -5 and height 10: both must be "
                                         "positive"):
        Recording(folder)


def test_an_id_twice_in_one_ground_truth_frame_names_the_file_frame_and_id(tmp_path):
    gt = [(1, 7, 10.0, 10.0, 5.0, 10.0, 1, 1, 1.0), (2, 7, 10.0, 10.0, 5.0, 10.0, 1, 1, 1.0),
          (2, 7, 30.0, 10.0, 5.0, 10.0, 1, 1, 1.0)]
    folder = write_sequence(tmp_path / "seq", det=[(1, 10.0, 10.0, 5.0, 10.0, 0.9)], gt=gt)
    with pytest.raises(ValueError, match=r"gt\.txt: frame 2 has id 7 in rows 2 and 3: a ground-truth id appears at "
                                         "most once a frame"):
        Recording(folder)
