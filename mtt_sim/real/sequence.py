"""A recorded MOTChallenge sequence as the env's source of ground truth, detections and frames.

A sequence folder (MOT15/16/17/20 layout) holds `seqinfo.ini`, `det/det.txt`, and optionally `gt/gt.txt` and the
frames in `img1/`. Detections are given to trackers exactly as written (raw confidences too); frames are read one at
a time when asked for. Ground truth is scored as TrackEval's MotChallenge2DBox scores the benchmark:
- MOT16/17/20: tracker boxes matched (Hungarian, IoU >= 0.5) to a ground-truth box of a distractor class
  (person on vehicle, static person, distractor, reflection; MOT20 also non-MOT vehicle) are removed, then only
  pedestrians (class 1) whose `considered` column is not 0 are scored;
- MOT15: no classes; rows whose `considered` column is 0 are not scored.
The truth the env shows holds the people (classes a person detector fires on) with their visible fraction: the
visibility column where the benchmark has one (MOT16/17/20; not used for scoring, as in TrackEval), else measured from
box overlaps (the box whose bottom edge is lower is nearer). With `sensor.model = "synthetic"` that truth is replayed
through the synthetic detector (a digital twin of the sequence) instead of reading det/det.txt; that detector is the
simulator's, handed in as `twin` (`mtt_sim.sources.open_source` does), so that this module needs nothing of the
simulator: its types and configuration tables live below both sources, in `mtt_sim.core`.

`Recording` implements `mtt_sim.sources.Source`, the interface a simulated scene implements too.
"""

from __future__ import annotations

import configparser
import copy
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Mapping

import cv2
import numpy as np

from mtt_sim.boxes import EPS, box_iou, match, occlusion_visibility
from mtt_sim.core.frame import Detections, ScoredTruth, Truth
from mtt_sim.core.settings import ConfigError, EnvConfig, ScoringConfig, SensorConfig, table
from mtt_sim.core.validate import build, expand_dotted, merge
from mtt_sim.real.layout import is_sequence

BENCHMARKS = ("MOT15", "MOT16", "MOT17", "MOT20")
PEDESTRIAN = 1
DISTRACTORS = {"MOT16": (2, 7, 8, 12), "MOT17": (2, 7, 8, 12), "MOT20": (2, 6, 7, 8, 12)}
PEOPLE = (1, 2, 7, 8, 12)  # pedestrian, person on vehicle, static person, distractor, reflection
VALID_CLASSES = range(1, 14)
FRAME_RATE = 30.0  # where there is no seqinfo.ini
REQUIRED_INFO = ("frameRate", "seqLength", "imWidth", "imHeight")  # what a seqinfo.ini must give
Twin = Callable[[SensorConfig, tuple[int, int], np.random.Generator], object]  # makes a detector: .detect(Truth)


@dataclass(frozen=True)
class SequenceConfig:
    """The configuration a recorded sequence runs with: the env's, the scoring's and (for its twin) the detector's
    tables; the image size, length and frame rate come from the sequence."""

    env: EnvConfig = table(EnvConfig, "the Gym face")
    scoring: ScoringConfig = table(ScoringConfig, "scoring and rewards")
    sensor: SensorConfig = table(SensorConfig, "the detector: 'recorded' reads det/det.txt, 'synthetic' is the twin")


@dataclass(frozen=True)
class SequenceInfo:
    """What seqinfo.ini says of a sequence (or, without one, what its frames and data imply)."""

    name: str
    width: int
    height: int
    frame_rate: float
    length: int
    image_dir: str = "img1"
    image_ext: str = ".jpg"


class Recording:
    """One sequence's detections, ground truth and frames, frame by frame (frame k = file frame k + 1), and the source
    that replays them: `reset`, then `observe` and `advance` frame by frame. `overrides` take env.*, scoring.* and
    sensor.* keys; sensor.model = "synthetic" replays the people through the synthetic detector (the twin) that `twin`
    makes (`mtt_sim.sim.sensor.twin_sensor`)."""

    detection_dtype = np.float64  # detections are handed on as written

    def __init__(self, folder, benchmark: str | None = None, overrides: Mapping | None = None,
                 twin: Twin | None = None):
        self.folder = Path(folder)
        if not is_sequence(self.folder):
            raise ConfigError(f"{folder}: not a MOTChallenge sequence folder (expected seqinfo.ini, det/det.txt or "
                                  "gt/gt.txt in it)")
        det_file, gt_file = self.folder / "det" / "det.txt", self.folder / "gt" / "gt.txt"
        det = read_rows(det_file, 7) if det_file.is_file() else np.zeros((0, 7))
        gt = read_rows(gt_file, 7) if gt_file.is_file() else None
        self.info = _read_info(self.folder, [det, gt if gt is not None else np.zeros((0, 7))])
        for path, rows in ((det_file, det), (gt_file, gt)):
            check_frames(path, rows, self.info.length)
        check_sizes(det_file, det)
        check_unique_ids(gt_file, gt)
        self.scored = gt is not None
        self.benchmark = benchmark or _benchmark_of(self.info.name, gt)
        if self.benchmark not in BENCHMARKS:
            raise ConfigError(f"benchmark={self.benchmark!r}: allowed values: {', '.join(map(repr, BENCHMARKS))}")
        self._det = by_frame(det, self.info.length)
        self._gt = by_frame(_gt_table(gt, self.benchmark, gt_file), self.info.length)
        for array in (*self._det, *self._gt):  # shared by every source `configured` from this one
            array.flags.writeable = False
        self.has_visibility = gt is not None and gt.shape[1] > 8 and self.benchmark != "MOT15"
        self.has_images = (self.folder / self.info.image_dir).is_dir()
        counts = np.diff(self._det[1])
        self.max_detections = int(counts.max()) if len(counts) else 0
        self.detection_rows = len(det)  # none: nothing to replay as recorded (open_source refuses it)
        self.truth_rows = 0 if gt is None else len(gt)  # none in a gt.txt: nothing to score (refused where scored)
        self.det_range = (det[:, 2:7].min(axis=0), det[:, 2:7].max(axis=0)) if len(det) else (np.zeros(5), np.zeros(5))
        self.image_size = (self.info.width, self.info.height)
        self.frame_rate, self.length = self.info.frame_rate, self.info.length
        self._start(overrides, twin)

    def configured(self, overrides: Mapping | None = None, twin: Twin | None = None) -> Recording:
        """A fresh source over the same sequence, its files not read again: this one's arrays shared (nothing writes
        them), configured anew with `overrides` (an env's own obs_mode, say) and `twin`."""
        new = copy.copy(self)
        new._start(overrides, twin)
        return new

    def _start(self, overrides: Mapping | None, twin: Twin | None) -> None:
        """Configured with `overrides` and `twin`, at the first frame."""
        self.config = self._configure(overrides or {})
        if self.config.sensor.model == "synthetic" and twin is None:
            raise ConfigError(f"{self.folder}: sensor.model = 'synthetic' replays the ground truth through the "
                              "simulator's detector: open the sequence with mtt_sim.sources.open_source, or pass "
                              "twin=mtt_sim.sim.sensor.twin_sensor")
        self.twin = twin
        self.sensor = None  # the twin's detector, while it runs
        self.k = 0

    def __len__(self) -> int:
        return self.info.length

    def detections(self, k: int) -> np.ndarray:
        """(n, 5) x, y, w, h, confidence of frame k, as written (none past the last frame)."""
        return _frame_rows(self._det, k)[:, 2:7]

    def _gt_rows(self, k: int) -> np.ndarray:
        return _frame_rows(self._gt, k)

    def truth(self, k: int) -> Truth:
        """The people of frame k (scored or not) as the env's Truth, with their visible fraction."""
        g = self._gt_rows(k)
        g = g[np.isin(g[:, 7], PEOPLE)]
        boxes, n = g[:, 2:6], len(g)
        visibility = g[:, 8] if self.has_visibility else occlusion_visibility(boxes, self.info.width, self.info.height)
        return Truth(ids=g[:, 1].astype(np.int64), boxes=boxes, visibility=visibility, visible_boxes=boxes,
                     depth=np.zeros(n), labels=np.zeros(n, int), pieces=np.zeros((0, 5)))

    def scoring(self, k: int, track_boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(scored GT ids, scored GT boxes, mask of the tracks that are scored) of frame k, by TrackEval's rules."""
        g = self._gt_rows(k)
        keep_tracks = np.ones(len(track_boxes), bool)
        if self.benchmark != "MOT15" and len(g) and len(track_boxes):
            rows, cols = match(box_iou(g[:, 2:6], track_boxes), 0.5 - EPS)
            keep_tracks[cols[np.isin(g[rows, 7], DISTRACTORS[self.benchmark])]] = False
        scored = (g[:, 6] != 0) & (g[:, 7] == PEDESTRIAN)  # MOT15's rows are all pedestrians (class 1)
        return g[scored, 1].astype(np.int64), g[scored, 2:6], keep_tracks

    def image(self, k: int) -> np.ndarray:
        """Frame k's image, RGB uint8 (H, W, 3), read from its file now."""
        path = self.folder / self.info.image_dir / f"{k + 1:06d}{self.info.image_ext}"
        img = cv2.imread(str(path), cv2.IMREAD_COLOR)
        if img is None:
            raise FileNotFoundError(f"{path}: frame {k + 1} of the sequence cannot be read")
        if img.shape[:2] != (self.info.height, self.info.width):
            raise ValueError(f"{path}: {img.shape[1]}x{img.shape[0]} pixels, but the sequence is "
                             f"{self.info.width}x{self.info.height} (seqinfo.ini)")
        return cv2.cvtColor(img, cv2.COLOR_BGR2RGB)

    def _configure(self, overrides: Mapping) -> SequenceConfig:
        """The configuration this sequence runs with: detection rows and episode length from the data; `env.*` and
        `scoring.*` keys can be overridden, and `sensor.*` keys for the synthetic detector (the twin)."""
        overrides = expand_dotted(overrides)
        other = sorted(set(overrides) - {"env", "scoring", "sensor"})
        if other:
            raise ConfigError(f"{self.folder}: a recorded sequence takes only env.*, scoring.* and sensor.* "
                                  f"overrides, not {other[0]}.*")
        sensor = overrides.get("sensor", {})
        model = sensor.get("model", "recorded")
        if model == "foreground":
            raise ConfigError(f"{self.folder}: sensor.model = 'foreground' needs frames the simulator rendered; "
                                  "a recorded sequence takes 'recorded' (its det/det.txt) or 'synthetic' (its twin)")
        if model == "recorded" and set(sensor) - {"model"}:
            key = sorted(set(sensor) - {"model"})[0]
            raise ConfigError(f"{self.folder}: sensor.{key} applies to the synthetic detector; add "
                                  "sensor.model = 'synthetic' (--detector synthetic) to replay the ground truth through it")
        obs_mode = overrides.get("env", {}).get("obs_mode")
        if obs_mode == "frame+detections" and not self.has_images:
            raise ConfigError(f"{self.folder}: env.obs_mode = 'frame+detections', but the sequence has no "
                                  f"{self.info.image_dir}/ folder of frames; use obs_mode='detections'")
        raw = {"sensor": {"model": "recorded", "max_detections": max(1, self.max_detections)} if model == "recorded"
               else {},
               "env": {"max_steps": self.info.length,
                       "obs_mode": "frame+detections" if self.has_images else "detections"}}
        return build(merge(raw, overrides), str(self.folder), SequenceConfig)

    # ------------------------------------------------------------ the source

    def detection_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Boxes in the image and confidences in the detector's range, widened to the extremes of det.txt where its
        rows are handed on as written (raw confidences included)."""
        (w, h), s = self.image_size, self.config.sensor
        low = np.array([0, 0, 0, 0, min(s.conf_offset, 0.0)])
        high = np.array([w, h, w, h, max(s.conf_offset + s.conf_scale, 0.0)])
        if s.model == "recorded":
            low, high = np.minimum(low, np.floor(self.det_range[0])), np.maximum(high, np.ceil(self.det_range[1]))
        return low, high

    def reset(self, world_rng: np.random.Generator, render_rng: np.random.Generator,
              sensor_rng: np.random.Generator) -> None:
        """Back to the first frame; the twin's detector starts afresh from `sensor_rng` (the others are unused)."""
        self.k = 0
        self.sensor = self.twin(self.config.sensor, self.image_size, sensor_rng) \
            if self.config.sensor.model == "synthetic" else None

    def observe(self, want_frame: bool) -> tuple[Truth, Detections, np.ndarray | None]:
        """The current frame's truth, detections and (if wanted) image: black past the end or without images."""
        k = self.k
        truth = self.truth(k)
        frame = self.image(k) if want_frame and self.has_images and k < len(self) else None
        if want_frame and frame is None:
            frame = np.zeros((self.info.height, self.info.width, 3), np.uint8)
        if self.sensor is not None:
            return truth, self.sensor.detect(truth), frame
        rows = self.detections(k)
        return truth, Detections(rows, np.full(len(rows), -1, np.int64)), frame

    def first_targets(self) -> tuple[np.ndarray, np.ndarray]:
        """Ids and boxes of the scored targets of the first frame (for trackers initialised by hand)."""
        return self.scoring(0, np.zeros((0, 4)))[:2]

    def scored_truth(self, track_boxes: np.ndarray) -> ScoredTruth:
        """`scoring` of the current frame, and no view of the hidden targets (a sequence has no occlusion windows)."""
        return ScoredTruth(*self.scoring(self.k, track_boxes), in_view=None)

    def advance(self) -> None:
        self.k += 1

    @property
    def finished(self) -> bool:
        return self.k >= len(self)


def _read_info(folder: Path, data: list[np.ndarray]) -> SequenceInfo:
    """seqinfo.ini's fields (a seqinfo.ini must give all four of REQUIRED_INFO); without one, the image files', then
    the data's (frame rate: 30)."""
    ini = configparser.ConfigParser()
    ini.optionxform = str
    path = folder / "seqinfo.ini"
    try:
        found = ini.read(path)
    except (configparser.Error, UnicodeDecodeError) as err:
        raise ConfigError(f"{path}: not an INI file with a [Sequence] section "
                              f"({str(err).splitlines()[0].rstrip('.')})") from None
    if found and "Sequence" not in ini:
        raise ConfigError(f"{path}: no [Sequence] section (expected name, frameRate, seqLength, imWidth, imHeight)")
    section = ini["Sequence"] if found else {}
    image_dir, image_ext = section.get("imDir", "img1"), section.get("imExt", ".jpg")
    images = sorted((folder / image_dir).glob(f"*{image_ext}")) if (folder / image_dir).is_dir() else []
    rows = np.concatenate([d[:, :6] for d in data])

    def number(key, kind, fallback):
        text = section.get(key)
        if text is None:
            return fallback()
        try:
            value = kind(text)
        except ValueError:
            value = 0
        if value <= 0:
            raise ConfigError(f"{folder / 'seqinfo.ini'}: {key} = {text!r}: expected a positive number")
        return value

    def image_size():
        if images:
            img = cv2.imread(str(images[0]), cv2.IMREAD_UNCHANGED)
            if img is not None:
                return img.shape[1], img.shape[0]
        corner = (rows[:, 2:4] + rows[:, 4:6]).max(axis=0) if len(rows) else np.ones(2)
        return int(np.ceil(max(corner[0], 16))), int(np.ceil(max(corner[1], 16)))

    width = number("imWidth", int, lambda: image_size()[0])
    height = number("imHeight", int, lambda: image_size()[1])
    length = number("seqLength", int, lambda: len(images) or int(rows[:, 0].max(initial=1)))
    frame_rate = float(number("frameRate", float, lambda: FRAME_RATE))
    missing = [key for key in REQUIRED_INFO if key not in section]
    if found and missing:  # a seqinfo.ini that leaves one out is a mistake, not a sequence to guess the size of
        raise ConfigError(f"{path}: [Sequence] has no {missing[0]}; a seqinfo.ini gives "
                              f"{', '.join(REQUIRED_INFO)} (leave the file out to take them from the frames and data)")
    return SequenceInfo(section.get("name", folder.name), width, height, frame_rate, length, image_dir, image_ext)


def read_rows(path: str | Path, min_columns: int) -> np.ndarray:
    """A MOTChallenge text file as a float array (rows, columns), with a clear error for a malformed one."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"{path}: not found")
    try:
        text = path.read_text().strip()
    except UnicodeDecodeError as err:
        raise ValueError(f"{path}: not a text file ({err}); expected comma-separated MOTChallenge rows (frame, id, x, "
                         "y, w, h, ...)") from None
    if not text:
        return np.zeros((0, min_columns))
    rows = []
    for number, line in enumerate(text.splitlines(), 1):
        values = line.replace(" ", "").split(",")
        if len(values) < min_columns:
            raise ValueError(f"{path}: row {number} has {len(values)} values, {line.strip()!r}; every row needs at "
                             f"least {min_columns} comma-separated values (frame, id, x, y, w, h, ...)")
        try:
            rows.append([float(v) for v in values])
        except ValueError:
            bad = next(v for v in values if not _is_number(v))
            raise ValueError(f"{path}: row {number}: {bad!r} is not a number ({line.strip()!r}); expected "
                             "comma-separated MOTChallenge rows (frame, id, x, y, w, h, ...)") from None
    if len({len(r) for r in rows}) > 1:
        number = next(i for i, r in enumerate(rows, 1) if len(r) != len(rows[0]))
        raise ValueError(f"{path}: row {number} has {len(rows[number - 1])} values, row 1 has {len(rows[0])}: every "
                         "row needs the same columns")
    rows = np.array(rows)
    if not np.isfinite(rows[:, :6]).all():
        raise ValueError(f"{path}: row {int(np.flatnonzero(~np.isfinite(rows[:, :6]).all(1))[0]) + 1} is not finite")
    return rows


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def check_frames(path: Path, rows: np.ndarray | None, length: int) -> None:
    """Frame numbers must lie in 1..length; a seqLength shorter than the data is an error, not a silent cut."""
    if rows is None or not len(rows):
        return
    frames = rows[:, 0]
    bad = (frames < 1) | (frames > length) | (frames != np.round(frames))
    if bad.any():
        raise ValueError(f"{path}: row {int(np.flatnonzero(bad)[0]) + 1} has frame {frames[bad][0]:g}, outside the "
                         f"sequence's 1..{length} (seqLength)")


def check_sizes(path: Path, rows: np.ndarray) -> None:
    """Every box must have a positive width and height."""
    bad = (rows[:, 4] <= 0) | (rows[:, 5] <= 0)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{path}: row {k + 1} (frame {rows[k, 0]:g}) has width {rows[k, 4]:g} and height "
                         f"{rows[k, 5]:g}: both must be positive (columns: frame, id, x, y, w, h, ...)")


def check_unique_ids(path: Path, rows: np.ndarray | None) -> None:
    """A ground-truth id appears at most once a frame."""
    if rows is None or not len(rows):
        return
    pairs = rows[:, :2]
    _, first, counts = np.unique(pairs, axis=0, return_index=True, return_counts=True)
    if (counts > 1).any():
        repeated = pairs[first[counts > 1][0]]
        where = np.flatnonzero((pairs == repeated).all(axis=1)) + 1
        raise ValueError(f"{path}: frame {repeated[0]:g} has id {repeated[1]:g} in rows {where[0]} and {where[1]}: a "
                         "ground-truth id appears at most once a frame")


def by_frame(rows: np.ndarray, length: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows sorted by frame (stable: file order within a frame) and where each frame's rows start (length + 1)."""
    order = np.argsort(rows[:, 0], kind="stable")
    rows = rows[order]
    return rows, np.searchsorted(rows[:, 0], np.arange(1, length + 2), side="left")


def _gt_table(gt: np.ndarray | None, benchmark: str, path: Path) -> np.ndarray:
    """gt rows as frame, id, x, y, w, h, considered, class, visibility: class 1 and visibility 1 where the benchmark's
    files have none (MOT15's later columns are world coordinates); classes are checked where they are used."""
    if gt is None:
        return np.zeros((0, 9))
    n, columns = gt.shape
    classes = gt[:, 7] if columns > 7 and benchmark != "MOT15" else np.ones(n)
    visibility = gt[:, 8] if columns > 8 and benchmark != "MOT15" else np.ones(n)
    bad = ~np.isin(classes, VALID_CLASSES)
    if bad.any():
        raise ValueError(f"{path}: row {int(np.flatnonzero(bad)[0]) + 1} has class {classes[bad][0]:g}, not one of "
                         f"{benchmark}'s classes 1..13 (pass benchmark='MOT15' to score without classes)")
    return np.c_[gt[:, :7], classes, visibility]


def _frame_rows(indexed: tuple[np.ndarray, np.ndarray], k: int) -> np.ndarray:
    """Frame k's rows of a `by_frame` table; none past the last frame."""
    rows, bounds = indexed
    return rows[bounds[k]: bounds[k + 1]] if k + 1 < len(bounds) else rows[:0]


def _benchmark_of(name: str, gt: np.ndarray | None) -> str:
    """MOT16/17/20 by the name's prefix; otherwise MOT17 where the ground truth has classes, else MOT15."""
    for bench in ("MOT16", "MOT17", "MOT20"):
        if name.upper().startswith(bench + "-"):
            return bench
    if gt is not None and gt.shape[1] >= 8 and len(gt) and np.isin(gt[:, 7], VALID_CLASSES).all():
        return "MOT17"
    return "MOT15"
