"""mtt-sim fit-scene: a scene fitted to a sequence's detections alone, on tiny sequences whose answers are known."""

import shutil

import numpy as np
import pytest

from helpers import write_sequence
from mtt_sim import cli
from mtt_sim.env import TrackingEnv
from mtt_sim.lab.episode import Episode
from mtt_sim.sim import scenario
from mtt_sim.sim2real import fit_scene

W, H, FRAMES = 640, 480, 30
A, B = 20.0, 0.5            # box height = A + B * feet row: near height 260, far/near 20/260
NEAR = A + B * H
NEAR_SPEED = 4.0            # px/frame at the bottom row; the image speed shrinks with the height, as the world's does
FEET = (200.0, 260.0, 330.0, 400.0, 460.0)


def walkers(direction=(1, 1, 1, 1, 1), late=None, heights=None):
    """One person per feet row, in every frame, walking along x at NEAR_SPEED times its depth scale; `late`: a sixth
    person entering at that frame."""
    rows = []
    people = [(y, d, 1) for y, d in zip(FEET, direction)] + ([(300.0, 1, late)] if late else [])
    for i, (y, d, first) in enumerate(people):
        h = heights[i] if heights is not None else A + B * y
        vx = d * NEAR_SPEED * (A + B * y) / NEAR
        for f in range(first, FRAMES + 1):
            x = (100.0 if d > 0 else 500.0) + 7 * i + vx * (f - 1)
            rows.append((f, x, y - h, 0.4 * h, h, 0.9))
    return rows


@pytest.fixture
def sensor(tmp_path):
    path = tmp_path / "sensor.toml"
    path.write_text('[sensor]\npreset = "ideal"\nclutter_rate = 0.0\nmerge_prob = 0.0\nfragment_prob = 0.0\n')
    return path


def fitted(folder):
    rows, info = fit_scene.link_sequence(folder)
    return fit_scene.fit(rows, info), rows, info


def test_estimates_equal_the_known_answers(tmp_path):
    raw, rows, info = fitted(write_sequence(tmp_path / "seq", walkers(), size=(W, H)))
    g = raw["groups"][0]
    assert (raw["render"], raw["env"]) == ({"width": W, "height": H, "camera": "still"}, {"max_steps": FRAMES})
    assert raw["world"]["projection"] == "standing"
    assert raw["world"]["far_scale"] == pytest.approx(A / NEAR, abs=1e-3)  # exact boxes: the line is exact
    assert g["size"] == pytest.approx([0.4 * NEAR, NEAR], abs=0.1)          # rounded to 0.1 px
    assert g["count"] == 5 and g["birth_rate"] == 0.0                        # every person in every frame
    assert g["speed"] == pytest.approx(NEAR_SPEED, abs=1e-3)                # exact boxes: the SORT boxes are them
    assert (g["heading"], g["heading_jitter"]) == (pytest.approx(0.0, abs=0.1), 45.0)
    assert (sides(raw, "entry"), sides(raw, "exit")) == (("left",), ("right",))  # all walk right
    feet = [d["rect"][1] + d["rect"][3] / 2 for d in raw["doors"]]            # doors in the band of the feet
    assert min(feet) >= g["region"][1] * H - 1 and max(feet) <= g["region"][3] * H + 1
    assert g["region"][1] == pytest.approx(FEET[0] / H, abs=0.02) and g["region"][3] == pytest.approx(FEET[-1] / H,
                                                                                                       abs=0.02)
    st = fit_scene.statistics(rows, info.length, H)
    assert st["people"] == 5.0 and st["far_near"] == pytest.approx(A / NEAR, abs=1e-3)


def test_a_late_person_is_a_birth_and_opposite_walkers_go_any_way(tmp_path):
    # SORT reports the late one once 3 matches have followed its first detection: 1 start after frame 1, and
    # 5 + (20 - 3) / 30 people per frame (it is detected in frames 11..30)
    raw, rows, info = fitted(write_sequence(tmp_path / "seq", walkers((1, -1, 1, -1, -1), late=11), size=(W, H)))
    g = raw["groups"][0]
    entries = [d for d in raw["doors"] if d["role"] == "entry"]
    assert g["birth_rate"] == 0.0 and sum(d["birth_rate"] for d in entries) == pytest.approx(1 / (FRAMES - 1),
                                                                                              abs=1e-3)
    assert fit_scene.statistics(rows, FRAMES, H)["people"] == pytest.approx(5 + 17 / 30)
    assert (g["heading"], g["heading_jitter"]) == (0.0, 180.0)
    # walking both ways: they come and go on both sides
    assert {sides(raw, "entry"), sides(raw, "exit")} == {("left", "right")}


def sides(raw: dict, role: str) -> tuple[str, ...]:
    """The borders (left, right) of a fitted scene's doors of `role`."""
    return tuple(sorted({"left" if d["rect"][0] < 0 else "right" for d in raw["doors"] if d["role"] == role}))


def test_heights_that_do_not_grow_downward_make_a_topdown_world(tmp_path):
    raw, _, _ = fitted(write_sequence(tmp_path / "seq", walkers(heights=[50.0] * 5), size=(W, H)))
    assert raw["world"] == {"projection": "topdown", "frame_rate": 10.0} and raw["groups"][0]["size"] == [20.0, 50.0]


def test_ground_truth_is_never_read(tmp_path, sensor):
    plain = write_sequence(tmp_path / "plain", walkers(), size=(W, H))
    labelled = tmp_path / "labelled"
    shutil.copytree(plain, labelled)
    (labelled / "gt").mkdir()
    (labelled / "gt" / "gt.txt").write_text("not,a,ground,truth\n!!\n")
    a, b = (fit_scene.fit_scene(f, sensor, seeds=()) for f in (plain, labelled))
    assert a[0] == b[0] and a[1] == b[1]


def test_the_written_scene_loads_and_runs(tmp_path, sensor):
    raw, real, scene, text = fit_scene.fit_scene(write_sequence(tmp_path / "seq", walkers(), size=(W, H)), sensor)
    assert set(real) == set(scene) == set(fit_scene.STAT_NAMES) and all(np.isfinite(list(scene.values())))
    path = tmp_path / "scene.toml"
    path.write_text(text)
    sc = scenario.load(path)
    assert sc.sensor.pd == 1.0 and sc.groups[0].count == 5 and sc.env.max_steps == FRAMES
    episode = Episode(TrackingEnv(path, obs_mode="detections"), seed=0, steps=20)
    for _ in episode:
        pass
    assert episode.steps == 20


def test_no_tracklets_is_an_error(tmp_path):
    folder = write_sequence(tmp_path / "seq", [(1, 10.0, 10.0, 20.0, 50.0, 0.9)], length=10, size=(W, H))
    with pytest.raises(scenario.ConfigError, match="no tracklets"):
        fitted(folder)


def test_the_command_writes_refuses_and_checks(tmp_path, sensor, capsys):
    folder = str(write_sequence(tmp_path / "seq", walkers(), size=(W, H)))
    out = str(tmp_path / "scene.toml")
    assert cli.main(["fit-scene", folder, "--sensor", str(sensor), "--out", out]) == 0
    printed = capsys.readouterr().out
    assert "people per frame" in printed and "fitted scene" in printed and "scene.toml" in printed
    assert scenario.load(out).groups[0].count == 5
    assert cli.main(["fit-scene", folder, "--sensor", str(sensor), "--out", out]) == 2
    assert "--force" in capsys.readouterr().err
    assert cli.main(["fit-scene", folder, "--sensor", str(sensor), "--out", out, "--force"]) == 0
    capsys.readouterr()
    with pytest.raises(SystemExit) as stop:
        cli.main(["fit-scene", str(tmp_path), "--sensor", str(sensor), "--out", str(tmp_path / "other.toml")])
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.count("\n") == 1 and "det/det.txt" in err


# ---------------------------------------------------------------- how the scene moves (fit_motion)

RATE, LONG = 10, 80          # write_sequence's seqinfo says 10 frames a second; 8 seconds
TALL = 100.0                 # px: every box's height
STEP = 0.5 * TALL / RATE     # px a frame: people walk half a height a second


def camera_path(frames=LONG, seed=3):
    """A hand-held camera's shift each frame (px; frame 1 none): a sway of 4 px a frame back and forth over two
    seconds, plus jitter."""
    rng = np.random.default_rng(seed)
    k = np.arange(frames)
    shift = np.c_[4.0 * np.sin(2 * np.pi * k / (2 * RATE)), 2.0 * np.cos(2 * np.pi * k / (1.3 * RATE))]
    shift += rng.normal(0, 1.5, (frames, 2))
    shift[0] = 0.0
    return shift


def moving_people(shift=None, standing=0):
    """Eight people, each in every frame: two walking right, two left, two up, two down at STEP px a frame (the last
    `standing` of them stand instead), all seen through a camera that moves by `shift` a frame."""
    path = np.cumsum(shift, axis=0) if shift is not None else np.zeros((LONG, 2))
    ways = [(1, 0), (1, 0), (-1, 0), (-1, 0), (0, 1), (0, 1), (0, -1), (0, -1)]
    starts = [(100, 150), (150, 330), (500, 200), (520, 360), (260, 60), (380, 90), (300, 300), (420, 330)]
    rows = []
    for i, ((dx, dy), (x0, y0)) in enumerate(zip(ways, starts)):
        v = 0.0 if i >= len(ways) - standing else STEP
        for f in range(LONG):
            x, y = x0 + dx * v * f + path[f, 0], y0 + dy * v * f + path[f, 1]
            rows.append((f + 1, float(x), float(y), 0.4 * TALL, TALL, 0.9))
    return rows


def test_a_camera_that_moves_is_told_apart_from_the_people(tmp_path):
    from mtt_sim.sim2real import fit_motion

    shift = camera_path()
    rows, info = fit_scene.link_sequence(write_sequence(tmp_path / "seq", moving_people(shift), size=(W, H)))
    moved = fit_motion.fit(rows, info)
    cam = moved["camera"]
    assert cam["moving"] and cam["r"] > 0.5
    # the shift a frame (px) recovered, as SORT's filter passes it on (it smooths the jitter a little)
    assert all(np.corrcoef(cam["shift"][1:, c], shift[1:, c])[0, 1] > 0.9 for c in (0, 1))
    assert np.median(np.abs(cam["shift"][1:] - shift[1:])) < 0.8
    assert moved["render"]["camera"] == "walking" and moved["render"]["camera_step"][0] > 0
    # the people's own motion, the camera taken out: half a height a second in straight lines (seen through the
    # camera, they would be fitted at 0.6 heights a second with a noise of 0.58)
    assert moved["walk"]["speed"] == pytest.approx(0.5, rel=0.1) and moved["walk"]["noise"] < 0.1
    stable = fit_motion.stabilise(fit_motion.track_rows(fit_motion.frames_of(rows, info.length)), cam["shift"])
    speeds = fit_motion.window_values(fit_motion.frames_from_tracks(stable, info.length), RATE)["speed"]
    assert np.median(speeds) == pytest.approx(0.5, rel=0.05)


def test_a_still_camera_stays_still_and_the_scene_keeps_the_sequence_clock(tmp_path, sensor):
    folder = write_sequence(tmp_path / "seq", moving_people(), size=(W, H))
    raw, _, _, text = fit_scene.fit_scene(folder, sensor, seeds=(), refine=False)
    assert raw["world"]["frame_rate"] == RATE and raw["walk"]["model"] == "langevin"
    assert raw["render"]["camera"] == "still"
    path = tmp_path / "scene.toml"
    path.write_text(text)
    sc = scenario.load(path)
    assert sc.world.frame_rate == RATE and sc.walk.model == "langevin" and sc.render.camera == "still"
    assert sc.walk.speed == pytest.approx(0.5, rel=0.2)


def test_people_who_stand_are_fitted_standing(tmp_path):
    from mtt_sim.sim2real import fit_motion, fit_walkers, motion
    from mtt_sim.sim.config import WalkConfig

    rows, info = fit_scene.link_sequence(write_sequence(tmp_path / "seq", moving_people(standing=6), size=(W, H)))
    walk = fit_motion.fit(rows, info)["walk"]
    assert walk["stop_rate"] / (walk["stop_rate"] + walk["go_rate"]) > 0.6  # six of eight stand, in the long run
    frames = fit_walkers.simulate(WalkConfig(**walk), RATE, people=60, duration=10.0)
    assert motion.people(frames, RATE)["standing"] > 0.5


def straight_walkers(speed: float, people: int = 8) -> tuple[np.ndarray, list]:
    """People walking along x at `speed` heights a second, each in every one of LONG frames: as tracklet rows (frame
    from 0, id, x, y, w, h) and as frames of (ids, boxes)."""
    from mtt_sim.sim2real import fit_motion

    step = speed * TALL / RATE
    rows = np.array([(f, i, 50.0 + step * f, 60.0 + 45 * i, 0.4 * TALL, TALL) for i in range(people)
                     for f in range(LONG)])
    return rows, fit_motion.frames_of(rows, LONG)


def test_refine_sets_the_desired_speed_at_which_the_scenes_people_walk_as_the_sequence_shows():
    """A scene whose people walk 0.7 times its desired speed; the sequence's tracklets walk half a height a second:
    the refinement sets the desired speed 0.5 / 0.7, read off the scene's people, not its tracklets (which here walk
    at twice the people's speed, as boxes that drift would show people faster than they walk)."""
    from mtt_sim.sim2real import fit_motion

    seq_rows, _ = straight_walkers(0.5)
    target = fit_motion.tracklet_motion(seq_rows, LONG, RATE)
    assert target[4] == pytest.approx(0.5)  # the median walking speed

    def scene(raw, seed):
        rows, _ = straight_walkers(2 * 0.7 * raw["walk"]["speed"])
        return rows, straight_walkers(0.7 * raw["walk"]["speed"])[1]

    raw = {"walk": {"model": "langevin", "speed": 0.4, "stop_rate": 0.1, "go_rate": 0.5, "noise": 0.1},
           "sensor": {"preset": "ideal"}}
    refined, history = fit_motion.refine(raw, target, scene, LONG, RATE, seeds=(0,))
    assert refined["walk"]["speed"] == pytest.approx(0.5 / 0.7, abs=1e-3)
    assert refined["walk"]["stop_rate"] == 0.1  # nobody stands, in the sequence or the scene
    assert history[1][2][4] == pytest.approx(0.7 * 0.4) and history[-1][0]["speed"] == refined["walk"]["speed"]
    # the sequence's people deviate from constant velocity by nothing, and the scene's whatever their noise: the noise
    # is deflated to the lowest the refinement tries, a tenth of the fit's
    assert refined["walk"]["noise"] == pytest.approx(0.01)


def walkers_and_standers(standing: int) -> tuple[np.ndarray, list]:
    """Six people walking half a height a second and `standing` more who hold still, in every one of LONG frames."""
    from mtt_sim.sim2real import fit_motion

    rows = straight_walkers(0.5, people=6)[0]
    if standing:
        rows = np.r_[rows, straight_walkers(0.0, people=standing)[0] + [0, 100, 0, 300, 0, 0]]
    return rows, fit_motion.frames_of(rows, LONG)


def test_refine_matches_who_stands_in_the_picture_of_a_camera_going_forward_with_its_companions():
    """Under a camera going forward the sequence's standing people walk with it (`fit_forward.companions`): the
    refinement adds companions until the scene stands as the sequence does, and leaves the walkers' stop rate (whose
    standing people would flow out with the ground) as fitted."""
    from mtt_sim.sim2real import fit_motion

    target = fit_motion.tracklet_motion(walkers_and_standers(2)[0], LONG, RATE)
    assert target[2] == pytest.approx(0.25)

    def scene(raw, seed):
        return walkers_and_standers(raw["render"].get("camera_companions", 0))

    raw = {"walk": {"model": "langevin", "speed": 0.5, "stop_rate": 0.1, "go_rate": 0.5, "noise": 0.1, "relax": 0.5},
           "render": {"camera_forward": 0.3}, "sensor": {"preset": "ideal"}}
    refined, _ = fit_motion.refine(raw, target, scene, LONG, RATE, seeds=(0,))
    assert refined["render"]["camera_companions"] == 2 and refined["walk"]["stop_rate"] == 0.1
    flat = {**raw, "render": {}}  # a camera that does not go forward: the stop rate is the lever
    refined, _ = fit_motion.refine(flat, target, scene, LONG, RATE, seeds=(0,))
    assert "camera_companions" not in refined["render"] and refined["walk"]["stop_rate"] > 0.1


def test_refine_sets_the_noise_that_brings_the_scenes_deviation_up_to_the_sequences(monkeypatch):
    """A fake scene whose tracklets deviate by sqrt(floor^2 + (k noise)^2) (the detector's deviation and the walkers'
    adding in squares): the refinement solves for the noise at which they deviate as the sequence's do."""
    from mtt_sim.sim2real import fit_motion

    floor, k, goal = 0.05, 0.8, 0.13
    seq_rows, _ = straight_walkers(0.5)
    target = fit_motion.tracklet_motion(seq_rows, LONG, RATE)
    target[1] = goal
    deviation, measured = {}, fit_motion._measured

    def scene(raw, seed):
        deviation["now"] = float(np.hypot(floor, k * raw["walk"]["noise"]))
        return straight_walkers(0.5)

    def with_deviation(values, jitter):  # the straight walkers' statistics, their deviation the fake scene's
        out = measured(values, jitter)
        out[1] = deviation["now"]
        return out

    monkeypatch.setattr(fit_motion, "_measured", with_deviation)
    raw = {"walk": {"model": "langevin", "speed": 0.5, "stop_rate": 0.1, "go_rate": 0.5, "noise": 0.1, "relax": 0.5},
           "sensor": {"preset": "ideal"}}
    refined, _ = fit_motion.refine(raw, target, scene, LONG, RATE, seeds=(0,))
    assert refined["walk"]["noise"] == pytest.approx(np.sqrt(goal ** 2 - floor ** 2) / k, abs=1e-4)
    assert refined["walk"]["relax"] == 0.5  # the fit's, kept


def test_refine_keeps_the_fits_noise_where_the_tracklets_are_too_few_to_read_a_deviation():
    """One person for eight seconds gives 60 one-second windows, fewer than MIN_WINDOWS: the fit kept the shipped
    relaxation and noise (fit_walkers), and the refinement does not move them off it by the few windows' deviation
    (the stop rate and the speed it still sets)."""
    from mtt_sim.sim2real import fit_motion

    seq_rows, _ = straight_walkers(0.5, people=1)
    target = fit_motion.tracklet_motion(seq_rows, LONG, RATE)
    assert target[5] == 60 < fit_motion.MIN_WINDOWS

    def scene(raw, seed):
        return straight_walkers(0.5)

    raw = {"walk": {"model": "langevin", "speed": 0.4, "stop_rate": 0.1, "go_rate": 0.5, "noise": 0.1, "relax": 0.5},
           "sensor": {"preset": "ideal"}}
    refined, history = fit_motion.refine(raw, target, scene, LONG, RATE, seeds=(0,))
    assert (refined["walk"]["noise"], refined["walk"]["relax"]) == (0.1, 0.5)
    assert refined["walk"]["speed"] == pytest.approx(0.4)  # its people walk the sequence's 0.5 already
    assert len(history) == 3  # the jitter's run and the two steps of the stop rate and the speed; no noise runs
    # with eight people (560 windows) the same scene's noise is deflated, as in the test above
    many = fit_motion.tracklet_motion(straight_walkers(0.5)[0], LONG, RATE)
    assert fit_motion.refine(raw, many, scene, LONG, RATE, seeds=(0,))[0]["walk"]["noise"] == pytest.approx(0.01)


FAR, AHEAD = -0.5, 0.3        # a horizon a third of the way down; a person at the bottom row grows 30 % a second


def ground_seen_going_forward(ahead=AHEAD, frames=LONG, companions=0):
    """Ten people standing on the ground, seen by a camera going forward at `ahead` (`mtt_sim.sim.forward`): each
    box's height is 200 px times the depth factor at its feet, so the height line gives the horizon back; a person is
    kept while the feet are inside the picture. `companions` more walk with the camera, beside the middle column."""
    from mtt_sim.sim import forward

    rng = np.random.default_rng(5)
    pos = np.c_[rng.uniform(60, W - 60, 10), rng.uniform(0.45 * H, 0.75 * H, 10)]
    along = np.c_[W / 2 + 80 * np.arange(companions), np.full(companions, 0.6 * H)]
    rows = []
    for f in range(frames):
        seen = np.r_[pos, along]
        h = 200.0 * (FAR + (1 - FAR) * seen[:, 1] / H)
        for (x, y), hi in zip(seen, h):
            if 0 < x < W and y < H:
                rows.append((f + 1, float(x - 0.2 * hi), float(y - hi), float(0.4 * hi), float(hi), 0.9))
        pos = forward.flow(pos, (W, H), FAR, ahead / RATE)
    return rows


def test_a_camera_going_forward_is_read_from_the_tracklets_growth_and_taken_out_of_the_walk(tmp_path):
    from mtt_sim.sim2real import fit_forward, fit_motion

    raw, rows, info = fitted(write_sequence(tmp_path / "seq", ground_seen_going_forward(), size=(W, H)))
    assert raw["world"]["far_scale"] == pytest.approx(FAR, abs=0.02)  # kept below 0: the horizon inside the picture
    assert raw["render"]["camera_forward"] == pytest.approx(AHEAD, rel=0.1)
    tracks = fit_motion.track_rows(fit_motion.frames_of(rows, info.length))
    assert fit_forward.evidence(fit_forward.windows(tracks, W, RATE)) > 0.95
    # nobody walks: with the flow taken out, the feet stay where they were (SORT's boxes lag a little as they grow)
    still = fit_forward.without(tracks, (W, H), FAR, AHEAD, RATE)
    assert np.median([np.ptp(r[:, 1:3], axis=0).max() / r[0, 3] for r in still.values()]) < 0.1
    walk, seen = raw["walk"], fit_motion.fit(rows, info)["walk"]  # the second as if the ground were flat
    assert walk["stop_rate"] / (walk["stop_rate"] + walk["go_rate"]) > 0.9 and seen["stop_rate"] == 0.0
    entry = [d for d in raw["doors"] if d["role"] == "entry"]  # the ground comes into view across the band
    assert len(entry) == 1 and entry[0]["rect"][2] == W


def test_people_who_hold_still_in_the_picture_of_a_camera_going_forward_walk_with_it(tmp_path):
    from mtt_sim.sim2real import fit_forward

    assert fit_forward.companions(np.r_[np.zeros(140), np.ones(500)], 110, 10) == 1  # 140 windows over 100 ends
    assert fit_forward.companions(np.r_[np.zeros(40), np.ones(500)], 110, 10) == 0
    raw = fitted(write_sequence(tmp_path / "two", ground_seen_going_forward(companions=2), size=(W, H)))[0]
    assert raw["render"]["camera_forward"] == pytest.approx(AHEAD, rel=0.1)
    assert raw["render"]["camera_companions"] == 2
    assert "camera_companions" not in fitted(write_sequence(tmp_path / "none", ground_seen_going_forward(),
                                                           size=(W, H)))[0]["render"]


def test_walkers_on_a_still_camera_show_no_forward_motion(tmp_path):
    from mtt_sim.sim2real import fit_forward, fit_motion

    rows, info = fit_scene.link_sequence(write_sequence(tmp_path / "seq", moving_people(), size=(W, H)))
    tracks = fit_motion.track_rows(fit_motion.frames_of(rows, info.length))
    assert abs(fit_forward.evidence(fit_forward.windows(tracks, W, RATE))) < fit_forward.MOVING_R
    assert "camera_forward" not in fit_motion.fit(rows, info, 0.2)["render"]


def test_the_jitter_scales_the_detectors_frame_to_frame_noise_and_keeps_its_drift():
    from mtt_sim.sim2real import fit_motion

    raw = {"sensor": {"box_noise": 0.02, "box_size_noise": 0.05, "box_drift": 0.06, "box_size_drift": 0.1}}
    sensor = fit_motion._detector_scaled(raw, 2.0)["sensor"]
    assert sensor == {"box_noise": 0.04, "box_size_noise": 0.1, "box_drift": 0.06, "box_size_drift": 0.1}
    assert fit_motion._detector_scaled(raw, 100.0)["sensor"]["box_noise"] == 0.08  # within NOISE_REACH (4)
