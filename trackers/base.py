"""The tracker interface: the Tracks result, the Tracker base class with validated parameters, the registry.

Trackers see what a tracker in the field sees, the observation (frame and detections), never
ground truth; hand-initialised trackers get the initial boxes from `reset(info)`, as their papers do.
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

import numpy as np

from . import plugins


@dataclass(frozen=True)
class Tracks:
    """A tracker's output for one frame: ids (m,), boxes (m, 4) x, y, w, h (float64, as computed), scores (m,)."""

    ids: np.ndarray
    boxes: np.ndarray
    scores: np.ndarray

    @classmethod
    def of(cls, ids, boxes, scores=None) -> "Tracks":
        ids = np.asarray(ids, np.int64).reshape(-1)
        boxes = np.asarray(boxes, np.float64).reshape(-1, 4)
        scores = np.ones(len(ids)) if scores is None else np.asarray(scores, np.float64).reshape(-1)
        return cls(ids, boxes, scores)

    def __len__(self) -> int:
        return len(self.ids)

    def to_action(self, action_space=None) -> dict:
        """The env action: padded to `action_space` (a gymnasium Dict space), in its box dtype, when given; else
        unpadded. Boxes with a non-positive side in that dtype are dropped: a box must have an area to be scored."""
        with np.errstate(over="ignore"):
            boxes = self.boxes if action_space is None else self.boxes.astype(action_space["boxes"].dtype)
        ok = (boxes[:, 2] > 0) & (boxes[:, 3] > 0) & np.isfinite(boxes).all(axis=1)
        ids, boxes = self.ids[ok], boxes[ok]
        if action_space is None:
            return {"ids": ids, "boxes": boxes}
        size = action_space["ids"].shape[0]
        if len(ids) > size:
            raise ValueError(f"{len(ids)} tracks do not fit the action space's {size} rows (env.max_tracks)")
        padded_ids, padded_boxes = np.zeros(size, np.int64), np.zeros((size, 4), boxes.dtype)
        padded_ids[: len(ids)], padded_boxes[: len(ids)] = ids, boxes
        return {"ids": padded_ids, "boxes": padded_boxes, "num_tracks": len(ids)}


def covariance_ellipse(centre, cov: np.ndarray, scale2: float, **style) -> dict:
    """A debug ellipse primitive: the set d^2 = scale2 of the 2-D Gaussian with covariance `cov` around `centre`;
    `style` is id=track id (drawn in its colour) or color=RGB."""
    eigval, eigvec = np.linalg.eigh(cov)
    angle = float(np.degrees(np.arctan2(eigvec[1, 1], eigvec[0, 1])))
    return {"kind": "ellipse", "center": centre, "axes": np.sqrt(scale2 * np.maximum(eigval[::-1], 0)), "angle": angle,
            **style}


def detections(obs: Mapping) -> np.ndarray:
    """The valid (n, 5) rows x, y, w, h, confidence of an observation, checked: the one gate between what a tracker
    is handed and its numpy code, so a malformed observation gets an error that names the problem."""
    if not isinstance(obs, Mapping) or "detections" not in obs or "num_detections" not in obs:
        raise ValueError("a tracker needs the env's observation: a dict with 'detections' and 'num_detections'"
                         + (f", got keys {sorted(map(str, obs))}" if isinstance(obs, Mapping) else
                            f", got {type(obs).__name__}"))
    try:
        rows = np.asarray(obs["detections"], np.float64)
    except (TypeError, ValueError):
        raise ValueError("observation 'detections' must be an (n, 5) array of numbers") from None
    if rows.ndim != 2 or rows.shape[1] != 5:
        raise ValueError(f"observation 'detections' must have shape (n, 5), got {rows.shape}")
    count = np.asarray(obs["num_detections"])
    if count.ndim != 0 or count.dtype.kind not in "iu" or not 0 <= int(count) <= len(rows):
        raise ValueError(f"observation 'num_detections' = {obs['num_detections']!r}: must be an integer in "
                         f"0..{len(rows)} (the rows of 'detections')")
    rows = rows[: int(count)]
    if not np.isfinite(rows).all():
        row = int(np.flatnonzero(~np.isfinite(rows).all(axis=1))[0])
        raise ValueError(f"observation detection row {row} is not finite")
    if not (rows[:, 2:4] > 0).all():
        row = int(np.flatnonzero((rows[:, 2:4] <= 0).any(axis=1))[0])
        raise ValueError(f"observation detection row {row} has a non-positive width or height: {rows[row].tolist()} "
                         "(boxes are x, y, w, h)")
    return rows


def frame_of(obs) -> np.ndarray:
    """The observation's video frame, an (H, W, 3) uint8 RGB image, or a clear error."""
    frame = obs.get("frame") if isinstance(obs, Mapping) else None
    if frame is None:
        raise ValueError("this tracker reads the video frame: make the env with obs_mode='frame+detections'")
    frame = np.asarray(frame)
    if frame.dtype != np.uint8 or frame.ndim != 3 or frame.shape[2] != 3 or not frame.size:
        raise ValueError(f"observation 'frame' must be an (H, W, 3) uint8 RGB image, got shape {frame.shape} and dtype "
                         f"{frame.dtype}")
    return frame


_INTERVAL = re.compile(r"^([\[(])(-inf|[-+0-9.e]+), (inf|[-+0-9.e]+)([\])])$")


@dataclass(frozen=True)
class Param:
    """A tracker parameter: its default and the values it may take. `allowed` is an interval for a number ("[0, 1]",
    "(0, inf)": brackets include the end, parentheses exclude it) or a tuple of choices for a string; None allows any
    finite number, any string. A bool takes true or false."""

    default: Any
    allowed: str | tuple[str, ...] | None = None
    meaning: str = ""  # what it is, with its unit
    search: tuple = ()  # where a tuner looks: (lo, hi) or (lo, hi, "log") for a number, the choices otherwise; () never
    needs: Mapping = field(default_factory=dict)  # switches it is read under, e.g. {"reid": True}: untuned otherwise

    def __post_init__(self):
        if isinstance(self.allowed, str) and not _INTERVAL.match(self.allowed):
            raise ValueError(f"Param allowed={self.allowed!r}: write an interval such as '[0, 1]' or '(0, inf)'")
        if self.search and self.numeric:
            kinds = (int,) if type(self.default) is int else (int, float)
            ends, scale = self.search[:2], list(self.search[2:])
            if not (len(ends) == 2 and all(type(e) in kinds for e in ends) and ends[0] < ends[1]
                    and all(map(self._allows, ends)) and scale in ([], ["log"]) and (not scale or ends[0] > 0)):
                raise ValueError(f"Param search={self.search!r}: a range (lo, hi) or (lo, hi, 'log') of "
                                 f"{'integers' if kinds == (int,) else 'numbers'} with lo < hi, both allowed "
                                 f"({self.allowed_text()}), lo > 0 on a log scale")
        elif self.search and not all(self._allows(c) and type(c) is type(self.default) for c in self.search):
            raise ValueError(f"Param search={self.search!r}: choices of the default's type, each allowed "
                             f"({self.allowed_text()})")

    @property
    def numeric(self) -> bool:
        return type(self.default) in (int, float)

    def suggest(self, trial, key: str):
        """This parameter's value for an Optuna trial, drawn from `search`."""
        if not self.numeric:
            return trial.suggest_categorical(key, list(self.search))
        lo, hi, *scale = self.search
        draw = trial.suggest_int if type(self.default) is int else trial.suggest_float
        return draw(key, lo, hi, log=bool(scale))

    def search_text(self) -> str:
        """Where a tuner looks, for listings: '[1, 10]', '[0.01, 1] log', 'true, false'; '' where it does not."""
        if not self.search:
            return ""
        if not self.numeric:
            return ", ".join(str(c).lower() if isinstance(c, bool) else repr(c) for c in self.search)
        lo, hi, *scale = self.search
        return f"[{lo:g}, {hi:g}]" + (" log" if scale else "")

    def allowed_text(self) -> str:
        kind = type(self.default)
        if kind is bool:
            return "true or false"
        if isinstance(self.allowed, tuple):
            return ", ".join(map(repr, self.allowed))
        what = {int: "an integer", float: "a number", str: "a string"}[kind]
        return what + (f" in {self.allowed}" if self.allowed else "")

    def check(self, tracker: str, key: str, value):
        """`value` converted to the default's type and inside the allowed values, or a ValueError saying which are."""
        out = _coerce(value, type(self.default))
        if out is None or not self._allows(out):
            raise ValueError(f"tracker {tracker!r}: parameter {key}={value!r}: allowed: {self.allowed_text()} "
                             f"(default {self.default!r})")
        return out

    def _allows(self, value) -> bool:
        if self.allowed is None or isinstance(value, bool):
            return True
        if isinstance(self.allowed, tuple):
            return value in self.allowed
        opening, lo, hi, closing = _INTERVAL.match(self.allowed).groups()
        lo, hi = float(lo), float(hi)
        return (lo < value or (opening == "[" and value == lo)) and (value < hi or (closing == "]" and value == hi))


def _coerce(value, kind):
    """`value` as a `kind` (bool, int, float or str; numpy numbers and text such as "3" or "true" too), or None."""
    if isinstance(value, np.generic):
        value = value.item()
    if kind is bool:
        if isinstance(value, str) and value.lower() in ("true", "false"):
            return value.lower() == "true"
        return value if isinstance(value, bool) else None
    if kind is str:
        return value if isinstance(value, str) else None
    if isinstance(value, bool):
        return None
    if kind is int and isinstance(value, int):
        return value
    try:
        number = float(value)
        out = kind(number) if kind is int else number
    except (TypeError, ValueError, OverflowError):
        return None
    if not np.isfinite(number) or (kind is int and out != number):
        return None
    return out


class Tracker:
    """Base class: subclasses set `name`, `description`, `parameters` (name -> Param) and implement `reset` and
    `update`. Parameters are checked against their allowed values when the tracker is made."""

    name = "tracker"
    description = ""
    parameters: dict[str, Param] = {}
    needs_frame = False  # True for trackers that read the video frame (appearance models)

    def __init__(self, **params):
        unknown = sorted(set(params) - set(self.parameters))
        if unknown:
            near = difflib.get_close_matches(unknown[0], self.parameters, n=1)
            raise ValueError(f"tracker {self.name!r}: unknown parameter {unknown[0]!r}"
                             + (f" (did you mean {near[0]!r}?)" if near else "") + "; allowed: "
                             + ", ".join(f"{k} (default {p.default!r})" for k, p in self.parameters.items()))
        self.params = {k: p.check(self.name, k, params.get(k, p.default)) for k, p in self.parameters.items()}

    def reset(self, info: Mapping | None = None) -> None:
        """Start a new episode; `info` is what env.reset returned."""

    def update(self, obs: Mapping) -> Tracks:
        raise NotImplementedError

    def results(self, online: list[Tracks]) -> list[Tracks]:
        """The tracks of every frame for a results file, given those it reported online: the same for an online method;
        an offline one (the IOU tracker) gives its own."""
        return online

    def debug(self) -> list[dict]:
        """Drawable internals of the last update for overlays, as plain dicts with a "kind": "ellipse" (center,
        axes, angle in degrees), "points" (xy (n, 2), optional "weights" and boolean "hidden"), "box" (box x, y, w,
        h), "text" (xy, text: a short tag), "bar" (box of the track, "value" in [0, 1]) or "data" (not drawn), and
        the track's "id" (drawn in its colour) or an RGB "color". May be empty."""
        return []


REGISTRY: dict[str, Callable[..., Tracker]] = {}


def register(cls, name: str | None = None):
    """Class decorator adding a tracker to the registry under its `name` (or `name`)."""
    REGISTRY[name or cls.name] = cls
    return cls


def available() -> dict[str, str]:
    """Registered tracker names, installed plugins' included, with their one-line descriptions."""
    plugins.load_plugins(register)
    return {name: cls.description for name, cls in sorted(REGISTRY.items())}


def tracker_class(name: str) -> type:
    """The class of a registered tracker (any letter case, installed plugins included) or of one named by location
    ('mypkg.mine:MyTracker', './mine.py:MyTracker'); a ValueError naming what is available otherwise."""
    if plugins.is_location(name):
        location, _, class_name = name.rpartition(":")
        if not location or not class_name:
            raise ValueError(f"tracker {name!r}: expected module:Class or path/to/file.py:Class")
        return plugins.load_class(location, class_name, Tracker)
    plugins.load_plugins(register)
    cls = REGISTRY.get(name.lower())
    if cls is None:
        near = difflib.get_close_matches(name.lower(), REGISTRY, n=1)
        raise ValueError(f"unknown tracker {name!r}" + (f" (did you mean {near[0]!r}?)" if near else "")
                         + f"; available: {', '.join(sorted(REGISTRY))}, or module:Class, or file.py:Class")
    return cls


def describe(name: str) -> list[str]:
    """A tracker's parameters, a line each: name=default, the allowed values, what it means and, for a tunable one,
    where a tuner looks."""
    return [f"{key + '=' + repr(param.default):34s} {param.allowed_text()}" + (f"; {param.meaning}" if param.meaning
                                                                               else "")
            + (f"; tuned in {param.search_text()}" if param.search else "")
            + "".join(f" with {k}={str(v).lower()}" for k, v in param.needs.items())
            for key, param in tracker_class(name).parameters.items()]


def search_space(name: str, fixed: Mapping = ()) -> dict[str, Param]:
    """The tunable parameters of a tracker, less those `fixed` (given in its spec) and those whose switch (`needs`) is
    not searched and is set, by the spec or by default, to a value under which they are never read."""
    params, given = tracker_class(name).parameters, dict(fixed) if isinstance(fixed, Mapping) else dict.fromkeys(fixed)
    searched = {key for key, p in params.items() if p.search and key not in given}

    def value(key):
        return params[key].check(name, key, given[key]) if given.get(key) is not None else params[key].default

    return {key: p for key, p in params.items() if key in searched
            and all(switch in searched or value(switch) == wanted for switch, wanted in p.needs.items())}


NAMESPACES = ("roboflow",)  # registered names of two parts: 'roboflow:sort'


def parse_spec(spec: str) -> tuple[str, dict[str, str]]:
    """'sort:max_age=3,min_hits=1' -> ('sort', {'max_age': '3', 'min_hits': '1'}); a tracker named by location keeps
    its class: './mine.py:Mine:gain=2' -> ('./mine.py:Mine', {'gain': '2'}), and one in a namespace its second part:
    'roboflow:sort:lost_track_buffer=60' -> ('roboflow:sort', {'lost_track_buffer': '60'})."""
    name, _, rest = str(spec).partition(":")
    if plugins.is_location(name.strip()) or name.strip().lower() in NAMESPACES:
        class_name, _, rest = rest.partition(":")
        name = f"{name.strip()}:{class_name.strip()}"
    params: dict[str, str] = {}
    for item in filter(None, (i.strip() for i in rest.split(","))):
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ValueError(f"tracker spec {spec!r}: expected name:key=value,key=value, e.g. 'sort:max_age=3,min_hits=1'")
        if key.strip() in params:
            raise ValueError(f"tracker spec {spec!r}: parameter {key.strip()!r} is given twice")
        params[key.strip()] = value.strip()
    return name.strip(), params


def spec_of(name: str, params: Mapping) -> str:
    """The spec of tracker `name` with these parameters, the inverse of `parse_spec`: ('sort', {'max_age': 3}) ->
    'sort:max_age=3'; floats written exactly, booleans as true and false."""
    def text(value) -> str:
        return str(value).lower() if isinstance(value, bool) else repr(value) if isinstance(value, float) else str(value)

    return name + (":" + ",".join(f"{k}={text(v)}" for k, v in params.items()) if params else "")


def split_specs(text: str) -> list[str]:
    """The tracker specs in one string: "sort,iou", "sort:min_hits=1,max_age=5,iou" (an item with "=" but no ":"
    continues the spec before it) or, separated by ";", "sort:min_hits=1,max_age=5;iou"."""
    specs: list[str] = []
    for part in text.split(";"):
        first = len(specs)
        for item in filter(None, (i.strip() for i in part.split(","))):
            if "=" in item and ":" not in item and len(specs) > first:
                specs[-1] += "," + item
            else:
                specs.append(item)
    return specs


def make(spec: str, **params) -> Tracker:
    """A tracker by name (in any letter case) or spec ('sort', 'sort:max_age=3', 'mypkg.mine:Mine:gain=2',
    './mine.py:Mine'); keyword parameters override the spec's."""
    name, spec_params = parse_spec(spec)
    return tracker_class(name)(**{**spec_params, **params})


class TrackerSpec(str):
    """A tracker spec parsed and checked once: the spec's text (a str, so that records, journal keys and worker tasks
    stay strings), its tracker's `name` and class, and the `params` it gives. Checking builds the tracker once, and
    that tracker is the first that `make` hands out: none is built only to be thrown away. Across processes it travels
    as the plain string, and each process parses it once again. `canonical`: the text names a registered tracker as
    registered ('SORT:max_age=3' -> 'sort:max_age=3')."""

    def __new__(cls, spec: str, canonical: bool = False) -> TrackerSpec:
        name, params = parse_spec(spec)
        kind = tracker_class(name)
        built = kind(**params)
        if canonical and not plugins.is_location(name):
            spec, name = built.name + spec.strip()[len(name):], built.name
        self = super().__new__(cls, spec)
        self.name, self.kind, self.params, self._built = name, kind, params, built
        self.registered, self.values = built.name, dict(built.params)  # as registered; every value, defaults filled
        return self

    @classmethod
    def of(cls, spec: str) -> TrackerSpec:
        """`spec` itself if it is one, else it parsed."""
        return spec if isinstance(spec, TrackerSpec) else cls(spec)

    def __reduce__(self):
        return str, (str(self),)

    def make(self) -> Tracker:
        """A new tracker of this spec (the first: the one its check built)."""
        built, self._built = self._built, None
        return built if built is not None else self.kind(**self.params)
