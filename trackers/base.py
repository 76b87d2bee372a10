"""The tracker interface: the Tracks result, the Tracker base class with validated parameters, the registry.

Trackers see what a tracker in the field sees, the observation (frame and detections), never
ground truth; hand-initialised trackers get the initial boxes from `reset(info)`, as their papers do.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping

import numpy as np


@dataclass(frozen=True)
class Tracks:
    """A tracker's output for one frame: ids (m,), boxes (m, 4) x, y, w, h, scores (m,)."""

    ids: np.ndarray
    boxes: np.ndarray
    scores: np.ndarray

    @classmethod
    def of(cls, ids, boxes, scores=None) -> "Tracks":
        ids = np.asarray(ids, np.int64).reshape(-1)
        boxes = np.asarray(boxes, np.float32).reshape(-1, 4)
        scores = np.ones(len(ids), np.float32) if scores is None else np.asarray(scores, np.float32).reshape(-1)
        return cls(ids, boxes, scores)

    def __len__(self) -> int:
        return len(self.ids)

    def to_action(self, action_space=None) -> dict:
        """The env action: padded to `action_space` (a gymnasium Dict space) when given, else unpadded.

        Boxes with a non-positive side are dropped: a box must have an area to be scored.
        """
        ok = (self.boxes[:, 2] > 0) & (self.boxes[:, 3] > 0) & np.isfinite(self.boxes).all(axis=1)
        ids, boxes = self.ids[ok], self.boxes[ok]
        if action_space is None:
            return {"ids": ids, "boxes": boxes}
        size = action_space["ids"].shape[0]
        if len(ids) > size:
            raise ValueError(f"{len(ids)} tracks do not fit the action space's {size} rows (env.max_tracks)")
        padded_ids, padded_boxes = np.zeros(size, np.int64), np.zeros((size, 4), np.float32)
        padded_ids[: len(ids)], padded_boxes[: len(ids)] = ids, boxes
        return {"ids": padded_ids, "boxes": padded_boxes, "num_tracks": len(ids)}


def covariance_ellipse(centre, cov: np.ndarray, scale2: float, color) -> dict:
    """A debug ellipse primitive: the set d^2 = scale2 of the 2-D Gaussian with covariance `cov` around `centre`."""
    eigval, eigvec = np.linalg.eigh(cov)
    angle = float(np.degrees(np.arctan2(eigvec[1, 1], eigvec[0, 1])))
    return {"kind": "ellipse", "center": centre, "axes": np.sqrt(scale2 * np.maximum(eigval[::-1], 0)), "angle": angle,
            "color": color}


def detections(obs: Mapping) -> np.ndarray:
    """The valid (n, 5) rows x, y, w, h, confidence of an observation, checked."""
    if not isinstance(obs, Mapping) or "detections" not in obs or "num_detections" not in obs:
        raise ValueError("a tracker needs the env's observation: a dict with 'detections' and 'num_detections'")
    rows = np.asarray(obs["detections"], np.float64)[: int(obs["num_detections"])]
    if rows.ndim != 2 or rows.shape[1] != 5:
        raise ValueError(f"observation 'detections' must have shape (n, 5), got {rows.shape}")
    if not np.isfinite(rows).all():
        raise ValueError(f"observation detection row {int(np.flatnonzero(~np.isfinite(rows).all(1))[0])} is not finite")
    return rows


def frame_of(obs) -> np.ndarray:
    """The observation's video frame, or a clear error for a detections-only env."""
    frame = obs.get("frame") if hasattr(obs, "get") else None
    if frame is None or np.ndim(frame) != 3 or np.size(frame) == 0:
        raise ValueError("this tracker reads the video frame: make the env with obs_mode='frame+detections'")
    return np.asarray(frame)


class Tracker:
    """Base class: subclasses set `name`, `description`, `defaults` and implement `reset` and `update`."""

    name = "tracker"
    description = ""
    defaults: dict[str, Any] = {}
    needs_frame = False  # True for trackers that read the video frame (appearance models)

    def __init__(self, **params):
        unknown = sorted(set(params) - set(self.defaults))
        if unknown:
            raise ValueError(f"tracker {self.name!r}: unknown parameter {unknown[0]!r}; allowed: "
                             + ", ".join(f"{k} (default {v!r})" for k, v in self.defaults.items()))
        self.params = {k: _coerce(self.name, k, params.get(k, v), v) for k, v in self.defaults.items()}

    def reset(self, info: Mapping | None = None) -> None:
        """Start a new episode; `info` is what env.reset returned."""

    def update(self, obs: Mapping) -> Tracks:
        raise NotImplementedError

    def debug(self) -> list[dict]:
        """Drawable internals of the last update for overlays, as plain dicts with a "kind": "ellipse" (center,
        axes, angle in degrees), "points" (xy (n, 2)), "box" (box x, y, w, h) or "text" (xy, text), and an
        optional RGB "color". May be empty."""
        return []


def _coerce(tracker: str, key: str, value, default):
    """A parameter value converted to the type of its default, or a clear error."""
    kind = type(default)
    if kind is bool:
        if isinstance(value, str) and value.lower() in ("true", "false"):
            return value.lower() == "true"
        if isinstance(value, bool):
            return value
    elif kind in (int, float):
        try:
            out = kind(value)
            if kind is int and float(value) != out:
                raise ValueError
            if np.isfinite(out):
                return out
        except (TypeError, ValueError):
            pass
    elif kind is str and isinstance(value, str):
        return value
    raise ValueError(f"tracker {tracker!r}: parameter {key}={value!r} must be a {kind.__name__}")


REGISTRY: dict[str, Callable[..., Tracker]] = {}


def register(cls):
    """Class decorator adding a tracker to the registry under its `name`."""
    REGISTRY[cls.name] = cls
    return cls


def available() -> dict[str, str]:
    """Registered tracker names with their one-line descriptions."""
    return {name: cls.description for name, cls in sorted(REGISTRY.items())}


def parse_spec(spec: str) -> tuple[str, dict[str, str]]:
    """'sort:max_age=3,min_hits=1' -> ('sort', {'max_age': '3', 'min_hits': '1'})."""
    name, _, rest = spec.partition(":")
    params = {}
    for item in filter(None, rest.split(",")):
        key, sep, value = item.partition("=")
        if not sep:
            raise ValueError(f"tracker spec {spec!r}: expected name:key=value,key=value")
        params[key.strip()] = value.strip()
    return name.strip(), params


def make(spec: str, **params) -> Tracker:
    """A tracker by name or spec ('sort', 'sort:max_age=3'); keyword parameters override the spec's."""
    name, spec_params = parse_spec(spec)
    if name not in REGISTRY:
        raise ValueError(f"unknown tracker {name!r}; available: {', '.join(sorted(REGISTRY))}")
    return REGISTRY[name](**{**spec_params, **params})
