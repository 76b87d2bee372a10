"""Calibration, the digital twin and the sim-to-real check, on hand-made sequence folders."""

import hashlib
import json
import shutil

import gymnasium as gym
import numpy as np
import pytest

import mtt_sim  # noqa: F401  (registers the env ids)
from helpers import exit_code, write_sequence
from mtt_sim import cli
from mtt_sim.sim2real import calibrate
from mtt_sim.lab.export import export_episode
from mtt_sim.sim import scenario
from mtt_sim.sim2real import validate
from mtt_sim.sim2real.fit_scene import fit_scene
from mtt_sim.lab.experiment import run_episode
from mtt_sim.env import NO_TRACKS
from mtt_sim.core.frame import Truth

KNOWN = {"model": "synthetic", "pd": 0.85, "pd_spread": 0.8, "miss_corr": 0.6, "visibility_slope": 3.0, "reference_height": 100.0,
         "min_visibility": 0.0, "box_noise": 0.03, "box_size_noise": 0.03, "box_drift": 0.05, "box_size_drift": 0.1,
         "box_drift_corr": 0.8, "box_scale": 1.1, "box_outlier_prob": 0.02, "box_outlier_persist": 0.3, "clutter_rate": 1.0,
         "site_rate": 0.1, "site_life": 15.0, "site_near": 0.3, "merge_prob": 0.0, "fragment_prob": 0.0,
         "conf_true": 0.9, "conf_visibility": 1.5, "conf_spread": 12.0, "conf_outlier": -1.5, "conf_false": 0.4,
         "conf_false_spread": 3.0}


def people(frames, count=8, spacing=150.0, life=100):
    """gt rows (MOT17 columns: class 1, visibility 1 or 0.6) of still people in `count` places, a new person in each
    place every `life` frames."""
    rows = []
    for f in range(1, frames + 1):
        k = (f - 1) // life
        rows += [(f, 1 + i + count * k, 20.0 + spacing * i, 60.0, 0.4 * (100.0 + 15 * i), 100.0 + 15 * i, 1, 1,
                  1.0 if (i + k) % 2 == 0 else 0.6) for i in range(count)]
    return rows


@pytest.fixture(scope="module")
def twin(tmp_path_factory):
    """A sequence whose detections are the synthetic detector's with the KNOWN keys (1,000 frames, 80 people)."""
    root = tmp_path_factory.mktemp("twin")
    gt = write_sequence(root / "People", gt=people(1000), size=(1280, 720))
    export_episode(gt, root / "twin", seed=3, config={"sensor": KNOWN})
    return root / "twin"


def test_calibrate_recovers_the_detector_that_made_the_detections(twin):
    fitted = calibrate.fit(calibrate.read(twin).associated)
    tolerance = {"pd": 0.05, "pd_spread": 0.25, "miss_corr": 0.08, "visibility_slope": 0.8, "box_noise": 0.008, "box_size_noise": 0.01,
                 "box_drift": 0.008, "box_size_drift": 0.01, "box_drift_corr": 0.05, "box_scale": 0.02,
                 "box_outlier_prob": 0.015, "box_outlier_persist": 0.1, "clutter_rate": 0.15, "site_rate": 0.04,
                 "site_life": 4.0, "conf_true": 0.02, "conf_visibility": 0.3, "conf_spread": 2.5, "conf_outlier": 0.3,
                 "conf_false": 0.03, "conf_false_spread": 0.6}
    # conf_spread: the fit reads the confidences' range off the data (padded by 1 %), which tightens them a little
    off = {k: (KNOWN[k], fitted[k]) for k, tol in tolerance.items() if abs(fitted[k] - KNOWN[k]) > tol}
    assert not off, off


def test_the_twin_of_a_twin_has_the_data_statistics_and_its_table_loads(twin, tmp_path):
    c = calibrate.calibrate([twin], seeds=2)
    for key in ("P(miss)", "P(miss | miss)", "mean miss run"):
        assert c.twin[key] == pytest.approx(c.data[key], rel=0.1), key
    # the people stand still, boxed exactly: the per-frame noise matched to the jitter stays the known one
    for key in ("box jitter, centre x", "box jitter, height"):
        assert c.twin[key] == pytest.approx(c.data[key], rel=0.1), key
    for key in ("box_noise", "box_size_noise"):
        assert c.sensor[key] == pytest.approx(KNOWN[key], abs=0.008), key
    # a site held beside a person also ends when the person leaves (here every 100 frames), which the fit reads as a
    # shorter site life: known to cost about a tenth of the false positives
    assert c.twin["false positives per frame"] == pytest.approx(c.data["false positives per frame"], rel=0.15)
    assert "recall, visibility 0.5-0.75" in calibrate.report(c)
    (tmp_path / "fitted.toml").write_text(calibrate.to_toml(c))
    assert scenario.read_sensor(tmp_path / "fitted.toml") == {"sensor": c.sensor}
    assert scenario.load("crossing", scenario.read_sensor(tmp_path / "fitted.toml")).sensor.pd == c.sensor["pd"]


def test_association_counts_true_detections_outliers_and_false_positives():
    boxes = np.array([[0.0, 0.0, 10.0, 20.0], [50.0, 0.0, 10.0, 20.0]])
    truth = Truth(ids=np.array([1, 2]), boxes=boxes, visibility=np.ones(2), visible_boxes=boxes, depth=np.zeros(2),
                  labels=np.array([1, 2]), pieces=np.zeros((0, 5)))
    dets = np.array([[1.0, 0.0, 10.0, 20.0, 0.9],      # IoU 0.82 with person 1: true
                     [54.0, 0.0, 10.0, 20.0, 0.5],     # IoU 0.43 with person 2: an outlier
                     [200.0, 0.0, 10.0, 20.0, 0.1]])   # nowhere near: a false positive
    a = calibrate.associate([truth], [dets])
    assert a.hit.tolist() == [True, False] and a.detected.tolist() == [True, True]
    assert sorted(a.det_kind.tolist()) == [0, 1, 2]
    assert a.iou[0] == pytest.approx(180 / 220)


def test_the_annotators_jitter_is_not_counted_twice(twin, tmp_path):
    """The twin's detections beside a ground truth whose boxes jitter (1 % of the height a frame, as an annotator's
    might). The residuals' moments count that jitter as the detector's, and a twin built on the jittering truth then
    has it twice: its boxes jump more than the detections. Matched to the detections' own jitter, they jump as much."""
    shaky = tmp_path / "shaky"
    shutil.copytree(twin, shaky)
    gt = np.loadtxt(shaky / "gt" / "gt.txt", delimiter=",")
    gt[:, 2:6] += np.random.default_rng(0).normal(0.0, 0.01, (len(gt), 4)) * gt[:, 5:6]
    np.savetxt(shaky / "gt" / "gt.txt", gt, delimiter=",", fmt="%.3f")
    source = calibrate.read(shaky)
    moments = calibrate.fit(source.associated)
    matched = calibrate.calibrate([shaky], seeds=1)
    twice = calibrate.twin_statistics([source], moments, 1)
    for key, noise in zip(("box jitter, centre x", "box jitter, height"), ("box_noise", "box_size_noise")):
        assert twice[key] > 1.1 * matched.data[key], key
        assert matched.twin[key] == pytest.approx(matched.data[key], rel=0.05), key
        assert matched.sensor[noise] < moments[noise], noise


def test_box_jitter_is_the_median_second_difference_over_the_height():
    """One still person, detected in four frames in a row with heights 100, 110, 100, 110 and the centre 0, 2, 0, 2
    px off: the second differences over three frames are -20 / 110 and 20 / 100 (height), -4 / 110 and 4 / 100 (x)."""
    truths, dets = [], []
    for f, (dh, dx) in enumerate([(0, 0), (10, 2), (0, 0), (10, 2)]):
        box = np.array([[100.0, 50.0, 40.0, 100.0]])
        truths.append(Truth(ids=np.array([1]), boxes=box, visibility=np.ones(1), visible_boxes=box,
                            depth=np.zeros(1), labels=np.array([1]), pieces=np.zeros((0, 5))))
        dets.append(np.array([[100.0 + dx, 50.0, 40.0, 100.0 + dh, 0.9]]))
    got = calibrate.statistics(calibrate.associate(truths, dets))
    assert got["box jitter, height"] == pytest.approx((20 / 110 + 20 / 100) / 2)
    assert got["box jitter, centre x"] == pytest.approx((4 / 110 + 4 / 100) / 2)


def test_run_lengths_break_where_the_chain_breaks():
    values = np.array([1, 1, 0, 1, 1, 1, 0, 1], bool)
    cont = np.array([0, 1, 1, 1, 0, 1, 1, 1], bool)  # a new person starts at row 4
    assert calibrate.run_lengths(values, cont).tolist() == [2, 1, 2, 1]


def twin_fingerprint(folder, sensor_file, seed):
    env = gym.make("mtt_sim/Replay-v0", sequence=str(folder), sensor=str(sensor_file))
    obs, _ = env.reset(seed=seed)
    digest = hashlib.sha256()
    for _ in range(30):
        digest.update(obs["detections"][: int(obs["num_detections"])].tobytes())
        obs, *_ = env.step(NO_TRACKS)
    return digest.hexdigest()


@pytest.fixture(scope="module")
def sensor_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("sensor") / "fitted.toml"
    path.write_text(calibrate.sensor_toml(KNOWN))
    return path


def test_the_twin_through_gym_make_is_seeded_and_byte_identical(tmp_path, sensor_file):
    folder = write_sequence(tmp_path / "Seq", gt=people(30, count=4), size=(640, 480))
    first, again, other = (twin_fingerprint(folder, sensor_file, s) for s in (5, 5, 6))
    assert first == again != other


def test_the_twin_exports_as_a_sequence_with_the_recording_ground_truth(tmp_path, sensor_file, capsys):
    folder = write_sequence(tmp_path / "Seq", gt=people(40, count=4), size=(640, 480))
    assert cli.main(["export", str(folder), "--detector", "synthetic", "--sensor", str(sensor_file), "--seed", "2",
                     "--out", str(tmp_path / "out")]) == 0
    out = tmp_path / "out"
    assert (out / "gt" / "gt.txt").read_text().splitlines() == (folder / "gt" / "gt.txt").read_text().splitlines()
    det = np.loadtxt(out / "det" / "det.txt", delimiter=",")
    assert 100 < len(det) < 250 and set(det[:, 0].astype(int)) <= set(range(1, 41))
    assert "name=Seq-twin-seed2" in (out / "seqinfo.ini").read_text()
    assert not (out / "img1").exists()


def test_calibrate_command_prints_the_fit_beside_the_data_and_writes_a_loadable_table(twin, tmp_path, capsys):
    out = tmp_path / "fitted.toml"
    assert cli.main(["calibrate", str(twin), "--out", str(out), "--seeds", "1"]) == 0
    text = capsys.readouterr().out
    assert "P(miss | miss)" in text and "mean hit run" in text and "false positives per frame" in text
    assert scenario.read_sensor(out)["sensor"]["pd"] == pytest.approx(KNOWN["pd"], abs=0.03)
    assert cli.main(["run", str(twin), "--sensor", str(out), "--steps", "20", "--json"]) == 0
    assert json.loads(capsys.readouterr().out.splitlines()[-1])["num_frames"] == 20


@pytest.mark.parametrize("argv, message", [
    (["calibrate", "{empty}", "--out", "{tmp}/f.toml"], "is not a sequence folder with gt/gt.txt and det/det.txt"),
    (["calibrate", "{twin}", "--out", "{tmp}/f.txt"], "must end in .toml"),
    (["run", "{twin}", "--sensor", "{tmp}/none.toml"], "no such sensor file"),
    (["run", "{twin}", "--sensor", "{tmp}/bad.toml"], "expected a [sensor] table"),
    (["run", "{twin}", "--detector", "recorded", "--sensor", "{tmp}/nomodel.toml"],
     "sensor.pd applies to the synthetic detector"),
    (["run", "{twin}", "--detector", "foreground"], "needs frames the simulator rendered"),
    (["validate", "{twin}", "--seeds", "0"], "must be an integer >= 1"),
])
def test_calibration_arguments_get_one_line_errors(twin, tmp_path, capsys, argv, message):
    (tmp_path / "empty").mkdir()
    (tmp_path / "bad.toml").write_text("[env]\nmax_steps = 3\n")
    (tmp_path / "nomodel.toml").write_text("[sensor]\npd = 0.5\n")
    argv = [a.format(empty=tmp_path / "empty", tmp=tmp_path, twin=twin) for a in argv]
    code = exit_code(argv)
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err


@pytest.fixture(scope="module")
def two_sequences(tmp_path_factory):
    root = tmp_path_factory.mktemp("validate")
    folders = []
    for k, count in enumerate((4, 5)):
        gt = write_sequence(root / f"Gt{k}", gt=people(80, count=count), size=(1280, 720))
        export_episode(gt, root / f"Seq{k}", seed=k, config={"sensor": KNOWN})
        folders.append(root / f"Seq{k}")
    return folders


def test_validate_compares_real_and_twin_metrics_for_every_twin(two_sequences):
    v = validate.validate(two_sequences, ("sort", "iou"), seeds=2)
    assert set(v.real) == {(s, t) for s in ("Seq0", "Seq1") for t in ("sort", "iou")}
    assert {k[0] for k in v.twin} == {t.name for t in validate.TWINS} and not v.failed
    g = validate.gaps(v, "fitted here", "MOTA")
    assert len(g) == 4
    by_hand = 100 * (v.twin["fitted here", "Seq1", "iou"]["MOTA"] - v.real["Seq1", "iou"]["MOTA"])
    assert g[3] == pytest.approx(by_hand)
    text = validate.markdown(v)
    assert "| Seq0 | sort |" in text and "memoryless, on the others" in text and "P(miss | miss)" in text


def test_validate_judges_the_label_free_fitted_scene_as_its_own_run_would(two_sequences, tmp_path, capsys):
    v = validate.validate(two_sequences, ("sort",), seeds=1, scene=True)
    assert {k[0] for k in v.twin} == {t.name for t in validate.TWINS + (validate.SCENE,)} and not v.failed
    # by hand: Seq0's scene, fitted to its detections with the detector calibrate fits on Seq1, and SORT on its seed 0
    others = calibrate.calibrate([two_sequences[1]], seeds=1).sensor
    scene = tmp_path / "scene.toml"
    scene.write_text(fit_scene(two_sequences[0], others, seeds=())[3])
    assert v.twin[validate.SCENE.name, "Seq0", "sort"]["MOTA"] == run_episode(str(scene), "sort", 0)["metrics"]["MOTA"]
    argv = ["validate", *map(str, two_sequences), "--trackers", "sort", "--seeds", "1", "--scene", "--dry-run"]
    assert cli.main(argv) == 0 and "1 real, 5 twins x 1 seeds" in capsys.readouterr().out


def test_kendall_tau_of_identical_rankings_is_one_and_of_reversed_minus_one():
    real = {("s", t): {"MOTA": m, "IDF1": m, "IDSW": 0.0} for t, m in zip("abc", (0.1, 0.5, 0.3))}
    twin = {("x", "s", t): {"MOTA": m, "IDF1": -m, "IDSW": 0.0} for t, m in zip("abc", (0.2, 0.6, 0.4))}
    v = validate.Validation(("s",), tuple("abc"), (validate.TWINS[0],), real, twin, {}, 1, ())
    assert validate.taus(v, "x", "MOTA").tolist() == [1.0] and validate.taus(v, "x", "IDF1").tolist() == [-1.0]


def test_validate_command_writes_its_tables(two_sequences, tmp_path, capsys):
    out = tmp_path / "check.md"
    argv = ["validate", *map(str, two_sequences), "--trackers", "sort", "--seeds", "1", "--out", str(out)]
    assert cli.main(argv) == 0
    assert "median abs MOTA gap" in out.read_text() and "Goals:" in capsys.readouterr().out


def test_average_precision_by_hand():
    # ranked: TP, FP, TP, (one person never found): recall 1/3 at precision 1, 2/3 at 2/3
    conf, true = np.array([0.9, 0.8, 0.7]), np.array([True, False, True])
    assert calibrate.average_precision(conf, true, 3) == pytest.approx(1 / 3 + 1 / 3 * 2 / 3)
    assert calibrate.average_precision(conf[::-1], true[::-1], 2) == pytest.approx(1 / 2 + 1 / 2 * 2 / 3)  # by conf
    assert calibrate.average_precision(np.array([0.9, 0.8]), np.array([False, True]), 1) == pytest.approx(0.5)
