"""The one source interface: a simulated scene, a recorded sequence and its twin give the env the same facts and the
same kind of frames, and the env's spaces and episode follow from those facts alone."""

import inspect

import numpy as np
import pytest

import mtt_sim
from helpers import tiny, write_sequence
from mtt_sim import TrackingEnv, sources
from mtt_sim.real.sequence import Recording
from mtt_sim.sim.scene import Scene
from mtt_sim.core.frame import Detections, ScoredTruth, Truth

A, B = (10.0, 10.0, 20.0, 40.0), (50.0, 20.0, 20.0, 40.0)
GT = [(1, 1, *A, 1, 1, 1.0), (1, 2, *B, 1, 1, 1.0), (2, 1, *A, 1, 1, 1.0)]
MEMBERS = [name for name in [*sources.Source.__annotations__, *vars(sources.Source)] if not name.startswith("_")]


@pytest.fixture
def folder(tmp_path):
    return write_sequence(tmp_path / "SEQ-01", det=[(1, *A, 0.9), (2, *B, 0.4)], gt=GT, length=2, size=(100, 80))


def opened(folder):
    """A scene, a recording and the recording's twin, each as open_source gives it."""
    return [sources.open_source(tiny()), sources.open_source(folder),
            sources.open_source(folder, {"sensor.model": "synthetic"})]


def test_open_source_decides_the_kind_from_what_is_named(folder):
    scene, recording, twin = opened(folder)
    assert isinstance(scene, Scene) and isinstance(recording, Recording) and isinstance(twin, Recording)
    assert isinstance(sources.open_source("crossing"), Scene)
    assert sources.resolve(folder) == folder and sources.resolve("mtt_sim/Crossing-v0") == "crossing"


def test_every_source_has_every_member_of_the_interface(folder):
    assert {"config", "image_size", "frame_rate", "length", "scored", "detection_dtype", "detection_bounds", "reset",
            "observe", "first_targets", "scored_truth", "advance", "finished"} <= set(MEMBERS)
    for source in opened(folder):
        missing = [m for m in MEMBERS if m not in dir(source)]
        assert not missing, f"{type(source).__name__} lacks {missing}"


def test_the_facts_of_each_kind(folder):
    scene, recording, twin = opened(folder)
    assert (scene.image_size, scene.frame_rate, scene.length, scene.scored) == ((200, 100), 25.0, None, True)
    assert (recording.image_size, recording.frame_rate, recording.length, recording.scored) == ((100, 80), 10.0, 2, True)
    assert scene.detection_dtype == np.float32 and recording.detection_dtype == twin.detection_dtype == np.float64
    assert recording.config.sensor.model == "recorded" and twin.config.sensor.model == "synthetic"
    low, high = recording.detection_bounds()  # widened to det.txt's rows as written
    assert low.tolist() == [0, 0, 0, 0, 0] and high.tolist() == [100, 80, 100, 80, 1]


def test_a_source_steps_through_its_frames(folder):
    for source in opened(folder):
        source.reset(*(np.random.default_rng(k) for k in range(3)))
        frames = 0
        while not source.finished and frames < 3:
            truth, detections, image = source.observe(want_frame=True)
            assert isinstance(truth, Truth) and isinstance(detections, Detections)
            assert image.shape == (source.image_size[1], source.image_size[0], 3) and image.dtype == np.uint8
            scored = source.scored_truth(np.zeros((0, 4)))
            assert isinstance(scored, ScoredTruth) and len(scored.ids) == len(scored.boxes)
            source.advance()
            frames += 1
        assert frames == (source.length or 3)


def test_the_recording_replays_det_txt_as_written_and_its_twin_detects_afresh(folder):
    _, recording, twin = opened(folder)
    for source in (recording, twin):
        source.reset(*(np.random.default_rng(k) for k in range(3)))
    rows = recording.observe(False)[1].rows
    np.testing.assert_array_equal(rows, [[*A, 0.9]])
    assert twin.observe(False)[1].rows.dtype == np.float32  # the synthetic detector's own rows


def test_the_env_reads_only_the_facts(folder):
    for what in (tiny(), folder):
        env = TrackingEnv(what, obs_mode="detections")
        obs, info = env.reset(seed=0)
        source = env.source
        assert info["image_size"] == source.image_size and info["frame_rate"] == source.frame_rate
        assert info["length"] == source.length and env.scored == source.scored
        assert env.observation_space["detections"].dtype == source.detection_dtype
        assert env.config is source.config


def test_the_env_module_never_asks_which_kind_of_source_it_holds():
    code = inspect.getsource(mtt_sim.env)
    assert "Recording" not in code and "Scene" not in code and "is_sequence" not in code


def test_naming_a_folder_that_is_no_sequence_says_so(tmp_path):
    with pytest.raises(mtt_sim.ConfigError, match="is a folder but not a MOTChallenge sequence"):
        sources.resolve(tmp_path)
    with pytest.raises(ValueError, match="benchmark='MOT17' applies to recorded sequences"):
        sources.open_source("crossing", benchmark="MOT17")
