"""MOTChallenge export and evaluation round trips, and third-party trackers in the Gym loop."""

import dataclasses
from types import SimpleNamespace

import cv2
import numpy as np
import pytest

import mtt_sim
from mtt_sim import trackers
from mtt_sim import cli
from mtt_sim.lab.export import export_episode
from mtt_sim.real import motchallenge
from mtt_sim.real import sequence as seq
from mtt_sim.env import TrackingEnv

STEPS = 40


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    folder = tmp_path_factory.mktemp("seq")
    summary = export_episode("mot17_like", folder, seed=0, steps=STEPS)
    return folder, summary


def in_process(spec):
    """`spec` on mot17_like seed 0 in the env: (per-frame tracks, detections, the env's metrics)."""
    env = TrackingEnv("mot17_like", config={"env.max_steps": STEPS})
    obs, info = env.reset(seed=0)
    tracker = trackers.make(spec) if isinstance(spec, str) else spec
    tracker.reset(info)
    tracks, dets = [], []
    while True:
        dets.append(obs["detections"][: int(obs["num_detections"])].copy())
        action = tracker.update(obs).to_action(env.action_space)
        tracks.append((action["ids"][: action["num_tracks"]], action["boxes"][: action["num_tracks"]]))
        obs, _, term, trunc, info = env.step(action)
        if term or trunc:
            return tracks, dets, info["metrics"]


def test_export_writes_a_mot17_sequence(sequence):
    folder, summary = sequence
    assert summary["frames"] == len(seq.Recording(folder)) == STEPS
    img = cv2.imread(str(folder / "img1" / f"{STEPS:06d}.jpg"))
    assert img.shape == (540, 960, 3) and not (folder / "img1" / f"{STEPS + 1:06d}.jpg").exists()
    gt = seq.read_rows(folder / "gt" / "gt.txt", 9)
    assert gt.shape == (summary["gt_rows"], 9) and set(gt[:, 7]) == {1} and (gt[:, 8] <= 1).all()
    _, dets, _ = in_process("echo")           # the same detections as a run without frames
    det = seq.read_rows(folder / "det" / "det.txt", 10)
    np.testing.assert_allclose(det[:, 2:7], np.concatenate(dets), rtol=1e-7)


def test_ground_truth_as_results_scores_perfectly(sequence, capsys):
    folder, _ = sequence
    gt = seq.read_rows(folder / "gt" / "gt.txt", 9)
    results = folder / "perfect.txt"
    motchallenge.write_results(results, motchallenge.per_frame(gt, STEPS))
    assert cli.main(["eval", "--gt", str(folder), "--results", str(results), "--json"]) == 0
    out = capsys.readouterr().out
    for key in ('"MOTA": 1.0', '"IDF1": 1.0', '"HOTA": 1.0', '"IDSW": 0', '"FP": 0', '"FN": 0'):
        assert key in out


def test_our_tracker_written_to_a_results_file_scores_as_in_process(sequence, tmp_path):
    folder, _ = sequence
    tracks, _, expected = in_process("sort")
    results = tmp_path / "sort.txt"
    motchallenge.write_results(results, tracks)
    assert motchallenge.evaluate_results(folder, results) == expected  # the boxes the env scored, read back exactly


def test_bad_results_files_get_clear_errors(sequence, tmp_path):
    folder, _ = sequence
    bad = tmp_path / "bad.txt"
    bad.write_text("1,2,3\n")
    with pytest.raises(ValueError, match=r"at least 6 comma-separated values \(frame, id, x, y, w, h"):
        motchallenge.evaluate_results(folder, bad)
    bad.write_text(f"{STEPS + 1},1,0,0,10,10\n")
    with pytest.raises(ValueError, match=rf"bad.txt: row 1 has frame 41, outside the sequence's 1..{STEPS}"):
        motchallenge.evaluate_results(folder, bad)
    bad.write_text("1,1,nan,0,10,10\n")
    with pytest.raises(ValueError, match="row 1 is not finite"):
        motchallenge.evaluate_results(folder, bad)
    with pytest.raises(mtt_sim.ConfigError, match="not a MOTChallenge sequence folder"):
        motchallenge.evaluate_results(tmp_path / "nowhere", bad)


class SortReferenceStyle:
    """A third-party tracker with the SORT reference code's interface: update(x1, y1, x2, y2, score) rows ->
    (x1, y1, x2, y2, id) rows. Here it runs our SORT underneath, so the result is known."""

    def __init__(self):
        self.inner = trackers.make("sort")
        self.inner.reset({})

    def update(self, dets):
        boxes = dets.copy()
        boxes[:, 2:4] -= boxes[:, :2]
        padded = np.zeros((max(len(boxes), 1), 5), np.float32)
        padded[: len(boxes)] = boxes
        t = self.inner.update({"detections": padded, "num_detections": len(boxes)})
        return np.c_[t.boxes[:, :2], t.boxes[:, :2] + t.boxes[:, 2:], t.ids]


def test_external_adapter_runs_a_third_party_tracker_in_the_gym_loop():
    _, _, ours = in_process("sort")
    _, _, theirs = in_process(trackers.External(factory=SortReferenceStyle, box_format="xyxy"))
    assert theirs.keys() == ours.keys()
    for key, value in ours.items():   # counts exactly; float32 boxes through x1, y1, x2, y2 and back: rounding only
        assert theirs[key] == (pytest.approx(value, rel=1e-6) if isinstance(value, float) else value), key
    with pytest.raises(ValueError, match="box_format='tlbr': allowed values: 'xywh', 'xyxy'"):
        trackers.External(SortReferenceStyle(), box_format="tlbr")
    with pytest.raises(TypeError, match="has no update"):
        trackers.External(object()).reset({})


@dataclasses.dataclass
class StandInDetections:
    """What a supervision tracker reads and writes of `sv.Detections`, for a test without supervision installed."""

    xyxy: np.ndarray
    confidence: np.ndarray
    class_id: np.ndarray
    tracker_id: np.ndarray | None = None


class SupervisionStyle:
    """A tracker with supervision's interface, running the SORT-reference-style one above underneath."""

    def __init__(self):
        self.inner = SortReferenceStyle()

    def update_with_detections(self, dets: StandInDetections) -> StandInDetections:
        rows = self.inner.update(np.c_[dets.xyxy, dets.confidence])
        return StandInDetections(rows[:, :4], np.ones(len(rows)), np.zeros(len(rows), int), rows[:, 4].astype(int))


def test_a_supervision_tracker_runs_in_the_gym_loop():
    _, _, ours = in_process("sort")
    _, _, theirs = in_process(trackers.SupervisionTracker(factory=SupervisionStyle,
                                                          detections_type=StandInDetections))
    for key, value in ours.items():
        assert theirs[key] == (pytest.approx(value, rel=1e-6) if isinstance(value, float) else value), key
    with pytest.raises(TypeError, match="has no update_with_detections"):
        trackers.SupervisionTracker(object(), detections_type=StandInDetections).reset({})
    lost = trackers.SupervisionTracker(SimpleNamespace(update_with_detections=lambda d: "nothing"),
                                       detections_type=StandInDetections)
    lost.reset({})
    with pytest.raises(ValueError, match="must return Detections with xyxy and tracker_id, got str"):
        lost.update({"detections": np.zeros((1, 5), np.float32), "num_detections": 0})


class Returns:
    """A model whose update() returns a fixed value."""

    def __init__(self, value):
        self.value = value

    def update(self, dets):
        return self.value


@pytest.mark.parametrize("value, pattern", [
    (None, r"\(m, >= 5\) array of boxes and track ids, got NoneType of shape \(\)"),
    ("tracks", r"got str"),
    ([[1, 2, 3, 4, 5], [1, 2]], r"got list"),
    (np.zeros((2, 4)), r"got ndarray of shape \(2, 4\)"),
    (np.zeros((2, 5, 1)), r"got ndarray of shape \(2, 5, 1\)"),
    ([[0, 0, 5, 5, np.nan]], r"row 0 is not finite"),
    ([[0, 0, 5, 5, 1.5]], r"track ids must be integers in 0..2\*\*31-1, row 0 has 1.5"),
    ([[0, 0, 5, 5, -1]], r"row 0 has -1"),
    ([[0, 0, 5, 5, 3], [9, 9, 12, 12, 3]], r"must be unique within a frame; repeated: \[3\]"),
])
def test_malformed_third_party_output_gets_one_clear_error(value, pattern):
    t = trackers.External(Returns(value))
    t.reset({})
    with pytest.raises(ValueError, match=pattern):
        t.update({"detections": np.zeros((1, 5)), "num_detections": 0})


def test_third_party_output_of_one_track_or_none_is_read():
    t = trackers.External(Returns([0, 0, 5, 6, 7]))
    t.reset({})
    tracks = t.update({"detections": np.zeros((1, 5)), "num_detections": 0})
    assert tracks.ids.tolist() == [7] and tracks.boxes.tolist() == [[0, 0, 5, 6]]
    t = trackers.External(Returns([]))
    t.reset({})
    assert len(t.update({"detections": np.zeros((1, 5)), "num_detections": 0})) == 0
