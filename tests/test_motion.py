"""How people and cameras move (`mtt_sim.sim2real.motion`, `mtt-sim motion`): hand-made walkers and warps whose
statistics are known, a bad trace named by its row, and the command on a tiny sequence and trace."""

import json
import shutil
import tomllib

import numpy as np
import pytest
from helpers import write_sequence

from mtt_sim import cli
from mtt_sim.sim import scenario
from mtt_sim.sim.camera import read_warps
from mtt_sim.sim.config import WalkConfig
from mtt_sim.sim2real import fit_walkers, motion

RATE = 10  # frames per second: a one-second window is 10 frames


def walker(ids, xs, ys, height=50.0):
    """Frames of (ids, boxes) for people whose foot points are at xs[k], ys[k] (one column a person)."""
    xs, ys = np.atleast_2d(np.asarray(xs, float).T).T, np.atleast_2d(np.asarray(ys, float).T).T
    return [(np.array(ids), np.c_[x - 10, y - height, np.full(len(x), 20.0), np.full(len(x), height)])
            for x, y in zip(xs, ys)]


def test_a_steady_walker_has_its_speed_no_deviation_and_no_turn():
    t = np.arange(60)
    stats = motion.people(walker([1], 100 + 2.0 * t, 300 + 0 * t), RATE)  # 2 px a frame: 20 px/s, 0.4 heights/s
    assert stats["speed"] == pytest.approx(0.4) and stats["deviation"] == pytest.approx(0.0, abs=1e-12)
    assert stats["standing"] == 0 and stats["turning"] == pytest.approx(0.0) and stats["time in view"] == 6.0
    assert stats["windows"] == 60 - RATE and stats["tracks"] == 1


def test_a_person_who_stops_deviates_by_the_distance_not_walked():
    x = np.r_[100 + 5.0 * np.arange(20), np.full(30, 195.0)]  # walks 1 height/s for 2 s, then stands for 3 s
    values = motion.window_values(walker([7], x, np.full(50, 300.0)), RATE)
    stats = motion.people(walker([7], x, np.full(50, 300.0)), RATE)
    assert values["deviation"].max() == pytest.approx(1.0)  # a second of walking guessed, none done: one height
    assert stats["standing"] == pytest.approx(np.mean(values["speed"] < 0.1)) and 0.4 < stats["standing"] < 0.6


def test_a_right_angle_turn_and_gaps_filled_linearly():
    x = np.r_[100 + 5.0 * np.arange(20), np.full(20, 195.0)]
    y = np.r_[np.full(20, 300.0), 300 + 5.0 * np.arange(1, 21)]
    frames = walker([3], x, y)
    assert motion.window_values(frames, RATE)["turning"].max() == pytest.approx(90.0)
    gappy = [f if k % 3 else (np.zeros(0, int), np.zeros((0, 4))) for k, f in enumerate(frames)]
    gappy[0], gappy[-1] = frames[0], frames[-1]  # seen first and last: everything between is filled
    filled = motion.track_rows(gappy)[3]
    assert len(filled) == 40 and np.allclose(filled[:, 1], x) and np.allclose(filled[:, 2], y)


def test_camera_translation_rotation_and_zoom_of_known_warps():
    angle = np.radians(0.5)
    shift = np.array([[1, 0, 3.0], [0, 1, 4.0]])  # 5 px a frame
    turn = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0]])
    zoom = np.array([[1.01, 0, 0], [0, 1.01, 0]])
    identity = np.array([[1.0, 0, 0], [0, 1, 0]])
    moved = motion.camera(np.array([identity] + [shift] * 9), 1000, 500)
    assert moved["translation median (px)"] == pytest.approx(5.0) and moved["translation p95 (width)"] == pytest.approx(0.005)
    assert moved["rotation (deg)"] == 0 and moved["zoom (%)"] == pytest.approx(0.0)
    assert motion.camera(np.array([identity, turn, turn]), 1000, 500)["rotation (deg)"] == pytest.approx(0.5)
    zoomed = motion.camera(np.array([identity, zoom]), 1000, 500)
    assert zoomed["zoom (%)"] == pytest.approx(1.0) and zoomed["translation median (px)"] == pytest.approx(
        np.hypot(5.0, 2.5))  # the centre moves as the image scales about its corner


def test_a_trace_is_read_as_written_and_a_bad_row_is_named(tmp_path):
    good = tmp_path / "GMC-good.txt"
    good.write_text("0\t1.0\t0.0\t0.0\t0.0\t1.0\t0.0\t\n1\t1.0\t0.0\t2.5\t0.0\t1.0\t-1.5\t\n")
    assert read_warps(good).tolist() == [[[1, 0, 0], [0, 1, 0]], [[1, 0, 2.5], [0, 1, -1.5]]]
    bad = tmp_path / "GMC-bad.txt"
    bad.write_text("0 1 0 0 0 1 0\n1 1 0 x 0 1 0\n")
    with pytest.raises(ValueError, match=r"GMC-bad.txt, row 2: '1 1 0 x 0 1 0' is not numbers"):
        read_warps(bad)
    bad.write_text("0 1 0 0 0 1 0\n5 1 0 0 0 1 0\n")
    with pytest.raises(ValueError, match=r"row 2: expected the frame index 1 and six finite numbers"):
        read_warps(bad)


def test_the_command_prints_people_and_cameras_side_by_side(tmp_path, capsys):
    gt = [(f, 1, 100.0 + 2 * f, 200.0, 20.0, 50.0, 1, 1, 1.0) for f in range(1, 41)]
    folder = write_sequence(tmp_path / "walk", det=[(1, 10.0, 10.0, 5.0, 5.0, 0.9)], gt=gt, size=(400, 300))
    trace = tmp_path / "GMC-cam.txt"
    trace.write_text("".join(f"{k} 1 0 {3.0 * (k > 0)} 0 1 {4.0 * (k > 0)}\n" for k in range(5)))
    assert cli.main(["motion", str(folder), "--trace", str(trace), "--trace-size", "1000x500", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["people"]["walk"]["speed"] == pytest.approx(0.4) and out["people"]["walk"]["standing"] == 0
    assert out["cameras"]["GMC-cam"]["translation median (px)"] == pytest.approx(5.0)
    assert cli.main(["motion"]) == 2 and "give sequence folders or scenarios" in capsys.readouterr().err
    assert cli.main(["motion", "mot17_moving", "crossing", "--steps", "60", "--json"]) == 0
    cameras = json.loads(capsys.readouterr().out)["cameras"]  # a scene's own camera, from its warps
    assert cameras["crossing"]["translation p95 (px)"] == 0 and cameras["mot17_moving"]["translation median (px)"] > 0.5


def test_a_sequence_with_ground_truth_alone_is_measured(tmp_path, capsys):
    gt = [(f, 1, 100.0 + 2 * f, 200.0, 20.0, 50.0, 1, 1, 1.0) for f in range(1, 41)]
    folder = write_sequence(tmp_path / "gt_only", gt=gt, size=(400, 300))
    shutil.rmtree(folder / "det")  # as the shared MOT17 ground truths come: no detections
    assert cli.main(["motion", str(folder), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["people"]["gt_only"]["speed"] == pytest.approx(0.4)


def test_the_walking_model_fitted_to_its_own_walkers_shows_their_statistics_again():
    truth = WalkConfig(model="langevin", speed=0.6, speed_jitter=0.2, relax=0.5, noise=0.3, stop_rate=0.1,
                       go_rate=0.3)
    frames = fit_walkers.simulate(truth, RATE, people=120, duration=30.0, seed=5)
    fitted = fit_walkers.fit([(frames, RATE)], frame_rate=RATE)
    assert fitted.model == "langevin" and fitted.stop_rate > 0 and fitted.go_rate > 0
    again = fit_walkers.statistics([motion.window_values(fit_walkers.simulate(fitted, RATE, seed=6), RATE)])
    wanted = fit_walkers.statistics([motion.window_values(frames, RATE)])
    assert again[:3] == pytest.approx(wanted[:3], rel=0.2) and again[3] == pytest.approx(wanted[3], abs=0.05)


def test_a_scene_walks_by_the_model_at_its_own_frame_rate_and_stands_as_fitted():
    stats = {}
    for rate in (25.0, 10.0):
        frames, frame_rate, _ = motion.scored_frames("mot17_like", {"walk.model": "langevin",
                                                                     "world.frame_rate": rate}, steps=400)
        assert frame_rate == rate
        stats[rate] = motion.people(frames, frame_rate)
    for s in stats.values():  # MOT17-02 and 09, which the defaults are fitted to: 0.14, 0.066, 0.41 pooled
        assert 0.05 < s["speed"] < 0.4 and 0.03 < s["deviation"] < 0.13 and s["standing"] >= 0.15
    assert stats[10.0]["speed"] == pytest.approx(stats[25.0]["speed"], rel=0.5)  # seconds, not frames


def test_fit_writes_the_camera_fitted_to_traces_as_keys_a_scene_takes(tmp_path, capsys):
    rng = np.random.default_rng(3)
    moving = tmp_path / "GMC-moving.txt"
    steps = np.cumsum(rng.standard_t(2, (400, 2)), axis=0) * 0.3 + [2.0, 0.5]  # a drifting, heavy-tailed walk
    moving.write_text("".join(f"{k} 1.001 0 {dx:.4f} 0 1.001 {dy:.4f}\n" for k, (dx, dy) in enumerate(steps)))
    out = tmp_path / "camera.toml"
    assert cli.main(["motion", "--trace", str(moving), "--fit", str(out)]) == 0
    fitted = tomllib.loads(out.read_text())["render"]
    assert fitted["camera"] == "walking" and set(fitted) > {"camera_step", "camera_tail", "camera_zoom"}
    scene = scenario.load("mot17_like", {f"render.{k}": v for k, v in fitted.items()})
    assert scene.render.camera == "walking" and list(scene.render.camera_step) == fitted["camera_step"]
    assert "fitted: " in capsys.readouterr().out
