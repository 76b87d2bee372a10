"""Roboflow's trackers in the Gym loop. `SupervisionTracker` runs any tracker written for Roboflow's `supervision`:
`update_with_detections(sv.Detections)` returning the detections it keeps with their `tracker_id`, as supervision's
ByteTrack and the trackers built on it do. `roboflow:sort`, `roboflow:bytetrack`, `roboflow:ocsort` and
`roboflow:botsort` are the trackers of Roboflow's `trackers` package (the `[peers]` extra), their parameters declared
here so that a spec is checked before the package is imported. Neither package is a dependency: supervision's
`Detections` is used when it is installed, or any class taking `xyxy`, `confidence` and `class_id` keywords is given
instead."""

from __future__ import annotations

import importlib.util
import sys
from importlib import metadata
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..base import Param, Tracker, Tracks, detections, frame_of
from .rows import to_tracks, track_rows


class SupervisionTracker(Tracker):
    """Wraps `model` (or a fresh `factory()` at every reset), whose `update_with_detections(dets)` takes a
    supervision `Detections` (xyxy float32 (n, 4), confidence (n,), class_id (n,) all 0) and returns one with
    `xyxy` and `tracker_id` for each track it reports. `detections_type` is the `Detections` class to build (by
    default `supervision.Detections`)."""

    name = "supervision"
    description = "any tracker with supervision's update_with_detections(Detections), run in the Gym loop"

    def __init__(self, model: Any = None, factory: Callable[[], Any] | None = None,
                 detections_type: type | None = None):
        super().__init__()
        if model is None and factory is None:
            raise ValueError("supervision: give the tracker object (model=...) or a factory that makes one")
        self.model, self.factory, self.detections_type = model, factory, detections_type

    def reset(self, info=None):
        if self.factory is not None:
            self.model = self.factory()
        if not callable(getattr(self.model, "update_with_detections", None)):
            raise TypeError(f"supervision: {type(self.model).__name__} has no update_with_detections(detections) "
                            "method")
        if self.detections_type is None:
            try:
                from supervision import Detections
            except ImportError:
                raise ImportError("supervision: `pip install supervision`, or pass detections_type= a class taking "
                                  "xyxy, confidence and class_id") from None
            self.detections_type = Detections

    def update(self, obs) -> Tracks:
        out = self.model.update_with_detections(as_detections(self.detections_type, detections(obs)))
        return tracked(out, "supervision: update_with_detections()")


def as_detections(detections_type: type, dets: np.ndarray):
    """Our (n, 5) rows x, y, w, h, confidence as supervision's Detections (xyxy float32, confidence, class 0)."""
    xyxy = np.c_[dets[:, :2], dets[:, :2] + dets[:, 2:4]].astype(np.float32)
    return detections_type(xyxy=xyxy, confidence=dets[:, 4].astype(np.float32), class_id=np.zeros(len(dets), int))


def tracked(out, what: str) -> Tracks:
    """The tracks in the Detections a tracker returned: boxes with a tracker_id, those under 0 left out (Roboflow's
    mark of a detection that no reported track holds)."""
    ids = getattr(out, "tracker_id", None)
    if ids is None or getattr(out, "xyxy", None) is None:
        raise ValueError(f"{what} must return Detections with xyxy and tracker_id, got {type(out).__name__}")
    rows = np.c_[np.asarray(out.xyxy, float).reshape(-1, 4), np.asarray(ids, float).reshape(-1)]
    return to_tracks(track_rows(rows[~(rows[:, 4] < 0)]), "xyxy")


def roboflow_package():
    """Roboflow's `trackers` package, loaded from its installed files: in a checkout of mtt-sim, whose tracker folder
    is also named `trackers`, `import trackers` run from the repository's root would find that folder instead."""
    module = sys.modules.get("trackers")
    if module is not None and hasattr(module, "SORTTracker"):
        return module
    try:
        init = Path(metadata.distribution("trackers").locate_file("trackers/__init__.py"))
    except metadata.PackageNotFoundError:
        init = None
    if init is None or not init.is_file():
        raise ImportError("the roboflow:* trackers need Roboflow's trackers package: pip install 'mtt-sim[peers]'")
    spec = importlib.util.spec_from_file_location("trackers", init, submodule_search_locations=[str(init.parent)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["trackers"] = module
    try:
        spec.loader.exec_module(module)
    except Exception:
        del sys.modules["trackers"]
        raise
    return module


class RoboflowTracker(Tracker):
    """One of Roboflow's trackers (`roboflow_class` of its `trackers` package), made afresh at every reset with the
    spec's parameters and fed supervision Detections (and, where it compensates camera motion, the frame as BGR)."""

    roboflow_class = ""

    @property
    def needs_frame(self) -> bool:
        return bool(self.params.get("enable_cmc", False))

    def reset(self, info=None):
        self.model = getattr(roboflow_package(), self.roboflow_class)(**self.params)
        from supervision import Detections  # a dependency of Roboflow's trackers

        self.detections_type = Detections

    def update(self, obs) -> Tracks:
        dets = as_detections(self.detections_type, detections(obs))
        frame = {"frame": np.ascontiguousarray(frame_of(obs)[..., ::-1])} if self.needs_frame else {}
        return tracked(self.model.update(dets, **frame), f"{self.name}: update()")


def _lifecycle(activation: float, consecutive: int, iou: float) -> dict[str, Param]:
    """The parameters Roboflow's trackers share, with one tracker's defaults."""
    return {"lost_track_buffer": Param(30, "[0, inf)", "frames a lost track is kept (at 30 frames/s)"),
            "frame_rate": Param(30.0, "(0, inf)", "the video's frames per second (scales lost_track_buffer)"),
            "track_activation_threshold": Param(activation, "[0, 1]", "least confidence of a detection that starts "
                                                                      "a track"),
            "minimum_consecutive_frames": Param(consecutive, "[1, inf)", "matches before a track is reported"),
            "minimum_iou_threshold": Param(iou, "[0, 1]", "least IoU of a match")}


def _without(params: dict[str, Param], *keys: str) -> dict[str, Param]:
    return {k: v for k, v in params.items() if k not in keys}


class RoboflowSort(RoboflowTracker):
    name, roboflow_class = "roboflow:sort", "SORTTracker"
    description = "Roboflow trackers' SORTTracker (needs the [peers] extra)"
    parameters = _lifecycle(0.25, 3, 0.3)


class RoboflowByteTrack(RoboflowTracker):
    name, roboflow_class = "roboflow:bytetrack", "ByteTrackTracker"
    description = "Roboflow trackers' ByteTrackTracker (needs the [peers] extra)"
    parameters = {**_lifecycle(0.7, 2, 0.1),
                  "high_conf_det_threshold": Param(0.6, "[0, 1]", "confidence splitting high from low detections")}


class RoboflowOcSort(RoboflowTracker):
    name, roboflow_class = "roboflow:ocsort", "OCSORTTracker"
    description = "Roboflow trackers' OCSORTTracker (needs the [peers] extra)"
    parameters = {**_without(_lifecycle(0.0, 3, 0.3), "track_activation_threshold"),
                  "direction_consistency_weight": Param(0.2, "[0, inf)", "weight of the direction term (inertia)"),
                  "high_conf_det_threshold": Param(0.6, "[0, 1]", "least confidence of a detection used"),
                  "delta_t": Param(3, "[1, inf)", "frames back to the observation a direction is measured from")}


class RoboflowBotSort(RoboflowTracker):
    name, roboflow_class = "roboflow:botsort", "BoTSORTTracker"
    description = "Roboflow trackers' BoTSORTTracker (needs the [peers] extra; reads the frame with enable_cmc)"
    parameters = {**_without(_lifecycle(0.7, 2, 0.0), "minimum_iou_threshold"),
                  "minimum_iou_threshold_first_assoc": Param(0.2, "[0, 1]", "least IoU of a first-round match"),
                  "minimum_iou_threshold_second_assoc": Param(0.5, "[0, 1]", "least IoU of a second-round match"),
                  "minimum_iou_threshold_unconfirmed_assoc": Param(0.3, "[0, 1]", "least IoU of a match with a track "
                                                                                  "not yet confirmed"),
                  "high_conf_det_threshold": Param(0.6, "[0, 1]", "confidence splitting high from low detections"),
                  "enable_cmc": Param(True, None, "camera-motion compensation from the frame"),
                  "cmc_method": Param("sparseOptFlow", ("sparseOptFlow", "orb", "sift", "ecc"),
                                      "how the camera's motion is estimated"),
                  "cmc_downscale": Param(2, "[1, inf)", "the frame's downscaling for it"),
                  "instant_first_frame_activation": Param(True, None, "report the first frame's tracks at once")}
