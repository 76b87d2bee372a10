"""Cameras that move like cameras: a replayed GMC trace moves the image, the label map and the truth together as its
warps say; export writes the warps back as written; the fitted models move like the traces they were fitted to; the
first cameras (static, pan, follow, shake) report the whole-pixel shifts they make."""

import numpy as np
import pytest

from mtt_sim import ConfigError
from mtt_sim.env import TrackingEnv
from mtt_sim.sim import camera as cam
from mtt_sim.sim.camera import read_warps

NO_TRACKS = {"ids": np.zeros(0, np.int64), "boxes": np.zeros((0, 4), np.float32)}


def write_trace(path, warps):
    """A GMC file as BoT-SORT writes it: the index, then six numbers with 6 decimals, each followed by a tab."""
    path.write_text("".join(f"{k}\t" + "".join(f"{v:.6f}\t" for v in np.ravel(w)) + "\n" for k, w in enumerate(warps)))
    return path


SCENE = """name = "OneStill"
[world]
walls = true
[render]
width = 320
height = 240
background = "flat"
camera = "trace"
[sensor]
preset = "ideal"
[[groups]]
count = 1
speed = 0.0
accel = 0.0
size = [40.0, 60.0]
size_jitter = 0.0
region = [0.45, 0.45, 0.55, 0.55]
"""


def one_still_target(tmp_path, warps, frames=None, **config):
    """An env of one unmoving 40 x 60 target in the middle of a 320 x 240 world, seen by a camera replaying
    `warps`; `config`: more dotted keys."""
    trace = write_trace(tmp_path / "gmc.txt", warps)
    (tmp_path / "scene.toml").write_text(SCENE)
    config = {"render.trace": str(trace), "env.max_steps": frames or len(warps) + 2, **config}
    return TrackingEnv(tmp_path / "scene.toml", config=config, obs_mode="frame+detections")


def episode(env, seed=0):
    """Each frame's (truth boxes, label map, frame, camera warp) over the env's episode."""
    obs, info = env.reset(seed=seed)
    out = [(env.truth.boxes.copy(), env.source.labels.copy(), obs["frame"], info["camera_warp"])]
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(NO_TRACKS)
        out.append((env.truth.boxes.copy(), env.source.labels.copy(), obs["frame"], info["camera_warp"]))
        done = terminated or truncated
    return out


def test_a_translating_trace_moves_a_still_targets_box_by_its_shifts(tmp_path):
    shifts = [(0, 0), (3, -2), (-1.5, 4), (0.25, 0.5), (7, 0)]
    warps = [cam.shift(*s) for s in shifts]
    frames = episode(one_still_target(tmp_path, warps))
    start = frames[0][0][0]
    total = np.zeros(2)
    for k, (boxes, _, _, warp) in enumerate(frames):
        if k < len(shifts):
            total += shifts[k]
            np.testing.assert_allclose(warp, warps[k], atol=1e-12)
        else:  # past the trace: the camera holds still
            np.testing.assert_array_equal(warp, cam.IDENTITY)
        np.testing.assert_allclose(boxes[0, :2], start[:2] + total, atol=1e-4)
        np.testing.assert_allclose(boxes[0, 2:], start[2:], atol=1e-4)


def test_a_zooming_turning_trace_takes_a_boxs_corners_where_the_warp_says(tmp_path):
    angle, scale = np.radians(2.0), 1.05
    c, s = scale * np.cos(angle), scale * np.sin(angle)
    turn = np.array([[c, -s, 6.0], [s, c, -3.0]])
    warps = [cam.IDENTITY, turn, turn, cam.shift(-2, 1)]
    frames = episode(one_still_target(tmp_path, warps))
    box = frames[0][0][0].astype(float)
    x0, y0, x1, y1 = box[0], box[1], box[0] + box[2], box[1] + box[3]
    corners = np.array([[x0, y0], [x1, y0], [x0, y1], [x1, y1]])
    for k in range(1, len(warps)):
        corners = corners @ warps[k][:, :2].T + warps[k][:, 2]
        lo, hi = corners.min(axis=0), corners.max(axis=0)
        np.testing.assert_allclose(frames[k][0][0], [*lo, *(hi - lo)], atol=1e-3)
    np.testing.assert_allclose(cam.warp_boxes(np.array([[0.0, 0.0, 2.0, 1.0]]), turn),
                               [[6 - s, -3, 2 * c + s, 2 * s + c]], atol=1e-12)


def test_the_label_map_and_the_frame_move_with_the_box(tmp_path):
    angle, scale = np.radians(3.0), 0.97
    c, s = scale * np.cos(angle), scale * np.sin(angle)
    warps = [cam.IDENTITY] + [np.array([[c, -s, 5.0], [s, c, -4.0]])] * 3 + [cam.shift(10.5, 2.25)] * 3
    env = one_still_target(tmp_path, warps, **{"render.background_color": [0, 0, 0]})
    for boxes, labels, frame, _ in episode(env):
        ys, xs = np.nonzero(labels == 1)
        assert len(xs) > 1000
        x, y, w, h = boxes[0]
        assert xs.min() >= np.floor(x) - 1 and xs.max() <= np.ceil(x + w) and ys.min() >= np.floor(y) - 1 \
            and ys.max() <= np.ceil(y + h)
        assert (labels == 1).sum() > 0.6 * w * h  # an ellipse fills pi/4 of its box; turned, its box grows
        painted = frame.sum(axis=2) > 30  # the target on the black background: where its labels are
        assert (painted & (labels == 1)).sum() >= 0.95 * (labels == 1).sum()
        assert (painted & (labels == 0)).sum() <= 0.05 * (labels == 1).sum()
        assert env.truth.visibility[0] == pytest.approx(1.0)


def test_an_occluded_targets_visibility_is_measured_through_the_warp(tmp_path):
    """A target half hidden behind an occluder, turned and zoomed: its visibility is its label pixels over those it
    shows with the occluder taken away."""
    angle, scale = np.radians(1.5), 1.03
    c, s = scale * np.cos(angle), scale * np.sin(angle)
    warps = [cam.IDENTITY] + [np.array([[c, -s, 0.0], [s, c, 0.0]])] * 4
    env = one_still_target(tmp_path, warps, occluders=[{"rect": [160.0, 0.0, 80.0, 240.0]}])
    env.reset(seed=0)
    for k in range(len(warps)):
        if k:
            env.step(NO_TRACKS)
        seen = (env.source.labels == 1).sum()
        r = env.source.renderer
        r.occluder_boxes = np.zeros((0, 4))
        r.occluder_depth, r.occluder_is_rect = np.zeros(0), np.zeros(0, bool)
        alone = (r.render(env.source.world, draw_frame=False)[1] == 1).sum()
        assert 0.2 < seen / alone < 0.8
        assert env.truth.visibility[0] == pytest.approx(seen / alone, abs=0.01)
        r.occluder_boxes = np.array([[160.0, 0.0, 80.0, 240.0]])
        r.occluder_depth, r.occluder_is_rect = np.full(1, np.inf), np.ones(1, bool)


def test_export_writes_a_replayed_trace_back_as_written(tmp_path):
    from mtt_sim.lab.export import export_episode

    rng = np.random.default_rng(1)
    warps = [cam.IDENTITY] + [np.c_[np.eye(2) + rng.normal(0, 0.002, (2, 2)), rng.normal(0, 3, 2)] for _ in range(7)]
    trace = write_trace(tmp_path / "in.txt", warps)
    written = trace.read_text().splitlines()
    config = {"render.width": 320, "render.height": 240, "render.camera": "trace", "render.trace": str(trace),
              "env.max_steps": 20}
    export_episode("mot17_like", tmp_path / "seq", seed=0, steps=6, config=config, frames=False)
    back = (tmp_path / "seq" / "gmc.txt").read_text().splitlines()
    assert back == written[:6]
    np.testing.assert_allclose(read_warps(tmp_path / "seq" / "gmc.txt"), np.array(warps[:6]), atol=5e-7)
    export_episode("mot17_like", tmp_path / "still", seed=0, steps=3, frames=False)
    assert (tmp_path / "still" / "gmc.txt").read_text() == "".join(
        f"{k}\t1.000000\t0.000000\t0.000000\t0.000000\t1.000000\t0.000000\t\n" for k in range(3))


def test_a_relative_trace_is_the_scenario_files_folder(tmp_path, monkeypatch):
    write_trace(tmp_path / "walk.txt", [cam.IDENTITY, cam.shift(2, 0)])
    scenario = tmp_path / "scene.toml"
    scenario.write_text('base = "mot17_like"\n[render]\ncamera = "trace"\ntrace = "walk.txt"\n')
    monkeypatch.chdir("/")
    env = TrackingEnv(scenario, obs_mode="detections")
    env.reset(seed=0)
    _, _, _, _, info = env.step(NO_TRACKS)
    np.testing.assert_array_equal(info["camera_warp"], cam.shift(2, 0))


def test_a_bad_trace_is_named_with_its_key_file_and_row(tmp_path):
    bad = tmp_path / "bad.txt"
    bad.write_text("0\t1\t0\t0\t0\t1\t0\n1\t1\t0\t2.5\t0\t1\n")
    with pytest.raises(ConfigError, match=r"render\.trace = .*bad\.txt.*row 2.*six finite numbers"):
        TrackingEnv("mot17_like", config={"render.camera": "trace", "render.trace": str(bad)})
    bad.write_text("0\t1\t0\t0\t0\t1\t0\n1\t1\t0\tx\t0\t1\t0\n")
    with pytest.raises(ConfigError, match=r"render\.trace = .*row 2.*not numbers"):
        TrackingEnv("mot17_like", config={"render.camera": "trace", "render.trace": str(bad)})
    bad.write_text("0\t1\t0\t0\t0\t1\t0\n1\t0\t0\t0\t0\t0\t0\n")
    with pytest.raises(ConfigError, match=r"render\.trace = .*frame 1.*flattens"):
        TrackingEnv("mot17_like", config={"render.camera": "trace", "render.trace": str(bad)})
    with pytest.raises(ConfigError, match=r"render\.trace = .*missing\.txt"):
        TrackingEnv("mot17_like", config={"render.camera": "trace", "render.trace": str(tmp_path / "missing.txt")})
    with pytest.raises(ConfigError, match=r"render\.trace: render\.camera = 'trace' needs a camera-motion file"):
        TrackingEnv("mot17_like", config={"render.camera": "trace"})
    with pytest.raises(ConfigError, match=r"foreground.*'walking'"):
        TrackingEnv("mot17_like", config={"render.camera": "walking", "sensor.model": "foreground"})


@pytest.mark.parametrize("mode", ["static", "pan", "follow", "shake"])
def test_the_first_cameras_report_the_whole_pixel_shift_they_make(mode):
    config = {"render.camera": mode, "render.shake": 6.0, "world.size": [1400.0, 800.0], "env.max_steps": 30}
    env = TrackingEnv("mot17_like", config=config, obs_mode="detections")
    _, info = env.reset(seed=2)
    np.testing.assert_array_equal(info["camera_warp"], cam.IDENTITY)
    camera = env.source.renderer.camera
    moved = 0
    for _ in range(30):
        before = camera.offset.copy()
        _, _, terminated, truncated, info = env.step(NO_TRACKS)
        expected = cam.shift(*(before - camera.offset))
        np.testing.assert_array_equal(info["camera_warp"], expected)
        moved += np.any(expected != cam.IDENTITY)
        if terminated or truncated:
            break
    assert (moved == 0) == (mode == "static")


def test_the_models_move_like_the_traces_they_are_fitted_to():
    """Traces drawn from the walking model: the model with the keys fitted to them moves as they do (the shift's
    median and 95th percentile, the zoom's median, the shift's correlation across)."""
    from mtt_sim.sim.scenario import load

    def moves(traces):
        parts = np.concatenate([cam.components(*t) for t in traces])
        shift = np.hypot(parts[:, 0], parts[:, 1])
        return np.array([np.median(shift), np.percentile(shift, 95), np.median(np.abs(parts[:, 3]))])

    sc = load("mot17_moving", {"render.camera": "walking", "render.camera_step": [0.004, 0.001],
                               "render.camera_tail": 3.0})
    traces = [(cam.model_warps(sc, 3000, np.random.default_rng(s)), 960, 540) for s in range(3)]
    fitted = cam.fit(traces, frames=10000)
    assert fitted["camera_step_corr"][0] == pytest.approx(sc.render.camera_step_corr[0], abs=0.05)
    assert fitted["camera_step"][0] > 2 * fitted["camera_step"][1]
    refitted = load("mot17_moving", {f"render.{k}": v for k, v in fitted.items()})
    again = [(cam.model_warps(refitted, 3000, np.random.default_rng(10 + s)), 960, 540) for s in range(3)]
    np.testing.assert_allclose(moves(again), moves(traces), rtol=0.2)
    still = load("mot17_like", {"render.camera": "still"})
    jitter = cam.fit([(cam.model_warps(still, 3000, np.random.default_rng(s)), 960, 540) for s in range(3)],
                     still=True, frames=10000)
    assert jitter["still_jitter"] == pytest.approx(still.render.still_jitter, rel=0.4)


def test_mot17_moving_walks_like_the_real_moving_cameras():
    """The camera of the shipped mot17_moving, measured from info["camera_warp"] by the same function as a trace."""
    from mtt_sim.sim2real.motion import camera

    env = TrackingEnv("mot17_moving", config={"env.max_steps": 300}, obs_mode="detections")
    warps = [w for *_, w in [(None, env.reset(seed=0)[1]["camera_warp"])]]
    for _ in range(299):
        warps.append(env.step(NO_TRACKS)[4]["camera_warp"])
    stats = camera(np.array(warps), 960, 540)
    # the four moving MOT17 traces, pooled (docs/camera_motion.md): median 0.00265, 95th percentile 0.0152 of the width
    assert 0.5 < stats["translation median (width)"] / 0.00265 < 2
    assert 0.5 < stats["translation p95 (width)"] / 0.0152 < 2
