"""Roboflow's trackers as specs (`roboflow:sort`, ...): parameters checked before the package is needed, and the
adapter's handling of what such a tracker is given and returns, against a stand-in package written by the test
(the real one, the `[peers]` extra, is measured in docs/peers.md)."""

import sys
from importlib import metadata

import numpy as np
import pytest

from mtt_sim import trackers
from mtt_sim.trackers.adapters import roboflow

STAND_IN = '''
import numpy as np

made = []


class SORTTracker:
    """Keeps every detection; the first is not yet confirmed (id -1), the others get ids 7, 8, ..."""

    def __init__(self, **params):
        made.append(params)
        self.frames = []

    def update(self, detections, frame=None):
        self.frames.append(frame)
        detections.tracker_id = np.array([-1] + [7 + k for k in range(len(detections.xyxy) - 1)])[:len(detections.xyxy)]
        return detections


BoTSORTTracker = SORTTracker
'''

DETECTIONS = '''
class Detections:
    def __init__(self, xyxy, confidence, class_id):
        self.xyxy, self.confidence, self.class_id = xyxy, confidence, class_id
'''


@pytest.fixture
def stand_in(tmp_path, monkeypatch):
    """A package named `trackers` installed under tmp_path (with its dist-info), and a `supervision` beside it."""
    for name, text in (("trackers", STAND_IN), ("supervision", DETECTIONS)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text(text)
        (tmp_path / f"{name}-9.9.dist-info").mkdir()
        (tmp_path / f"{name}-9.9.dist-info" / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\n"
                                                                      "Version: 9.9\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "trackers", raising=False)
    monkeypatch.delitem(sys.modules, "supervision", raising=False)
    return tmp_path


def obs(rows, frame=None):
    rows = np.array(rows, float).reshape(-1, 5)
    return {"detections": rows, "num_detections": np.int64(len(rows)),
            **({} if frame is None else {"frame": frame})}


def test_specs_are_checked_without_the_package(monkeypatch):
    with pytest.raises(ValueError, match=r"tracker 'roboflow:sort': parameter lost_track_buffer='-1': allowed: an "
                                         r"integer in \[0, inf\)"):
        trackers.make("roboflow:sort:lost_track_buffer=-1")
    with pytest.raises(ValueError, match=r"unknown parameter 'delta_t'"):
        trackers.make("roboflow:bytetrack:delta_t=2")
    with pytest.raises(ValueError, match=r"cmc_method='flow': allowed: 'sparseOptFlow', 'orb', 'sift', 'ecc'"):
        trackers.make("roboflow:botsort:cmc_method=flow")

    def missing(name):
        raise metadata.PackageNotFoundError(name)

    monkeypatch.setattr(roboflow.metadata, "distribution", missing)
    monkeypatch.delitem(sys.modules, "trackers", raising=False)
    with pytest.raises(ImportError, match=r"pip install 'mtt-sim\[peers\]'"):
        trackers.make("roboflow:sort").reset({})


def test_a_roboflow_tracker_gets_its_parameters_and_reports_only_confirmed_tracks(stand_in):
    t = trackers.make("roboflow:sort:lost_track_buffer=60,minimum_consecutive_frames=1")
    t.reset({})
    made = sys.modules["trackers"].made
    assert made == [{"lost_track_buffer": 60, "frame_rate": 30.0, "track_activation_threshold": 0.25,
                     "minimum_consecutive_frames": 1, "minimum_iou_threshold": 0.3}]
    out = t.update(obs([[10, 20, 30, 40, 0.9], [100, 50, 20, 60, 0.8], [5, 5, 10, 10, 0.7]]))
    assert out.ids.tolist() == [7, 8]
    np.testing.assert_allclose(out.boxes, [[100, 50, 20, 60], [5, 5, 10, 10]])
    assert t.model.frames == [None]  # SORT reads no frame


def test_the_package_is_found_where_a_folder_named_trackers_would_shadow_it(stand_in, monkeypatch):
    """From the root of an mtt-sim checkout, `import trackers` finds mtt-sim's own tracker folder."""
    shadow = type(sys)("trackers")
    monkeypatch.setitem(sys.modules, "trackers", shadow)
    assert roboflow.roboflow_package() is not shadow
    assert hasattr(sys.modules["trackers"], "SORTTracker")


def test_botsort_with_camera_motion_compensation_reads_the_frame_as_bgr(stand_in):
    t = trackers.make("roboflow:botsort")
    assert t.needs_frame and not trackers.make("roboflow:botsort:enable_cmc=false").needs_frame
    t.reset({})
    rgb = np.zeros((4, 6, 3), np.uint8)
    rgb[..., 0] = 255  # red
    t.update(obs([[1, 1, 2, 2, 0.9]], frame=rgb))
    assert t.model.frames[0][0, 0].tolist() == [0, 0, 255]
    with pytest.raises(ValueError, match="reads the video frame"):
        t.update(obs([[1, 1, 2, 2, 0.9]]))


def test_commands_take_roboflow_specs_in_any_letter_case():
    from mtt_sim.cli.arguments import tracker_specs

    assert tracker_specs("Roboflow:Sort:lost_track_buffer=3;SORT") == ["roboflow:sort:lost_track_buffer=3", "sort"]
