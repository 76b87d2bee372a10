"""Where each step's ground truth, detections and frame come from: a simulated scene or a recorded sequence.

Both implement `Source`; `TrackingEnv` holds one and never asks which kind it is. `open_source` is the one place that
decides, from what the user named: a shipped scenario key, a scenario TOML file, an existing `Scenario`, or a
MOTChallenge sequence folder (replayed as recorded, or through the synthetic detector: its digital twin).
"""

from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import TYPE_CHECKING, Mapping, Protocol

import numpy as np

from mtt_sim.core.frame import Detections, ScoredTruth, Truth
from mtt_sim.core.settings import ConfigError
from mtt_sim.real.layout import is_sequence
from mtt_sim.sim import scenario
from mtt_sim.sim.config import Scenario

if TYPE_CHECKING:
    from mtt_sim.real.sequence import Recording, SequenceConfig
    from mtt_sim.sim.scene import Scene


class Source(Protocol):
    """What the env needs of a source: a few facts, then frame by frame the truth, detections and image."""

    config: Scenario | SequenceConfig  # its env.*, scoring.* and sensor.* tables (a scenario has more)
    image_size: tuple[int, int]        # width, height in pixels
    frame_rate: float                  # frames per second
    length: int | None                 # frames; None where the source ends when its world does
    scored: bool                       # whether there is ground truth to score against
    detection_dtype: type              # of the observation's detection rows

    def detection_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lowest and highest values of a detection row (x, y, w, h, confidence)."""

    def reset(self, world_rng: np.random.Generator, render_rng: np.random.Generator,
              sensor_rng: np.random.Generator) -> None:
        """Start over at the first frame, drawing from these independent generators."""

    def observe(self, want_frame: bool) -> tuple[Truth, Detections, np.ndarray | None]:
        """The current frame's ground truth (everyone in view), detections and, if wanted, RGB image."""

    def first_targets(self) -> tuple[np.ndarray, np.ndarray]:
        """Ids and boxes of the targets of the first frame, for trackers initialised by hand."""

    def scored_truth(self, track_boxes: np.ndarray) -> ScoredTruth:
        """What the current frame's tracks (these boxes) are scored against: the scored targets, which of the tracks
        are scored, and everyone in view for the occlusion windows (or None)."""

    def advance(self) -> None:
        """Move on to the next frame."""

    @property
    def finished(self) -> bool:
        """Whether the episode is over (nothing left to track, or past the last frame)."""


def resolve(name: str | os.PathLike) -> str | Path:
    """What a user named: a shipped scenario key (in any case or as its env id), a .toml file or a sequence folder
    (both as Paths); an error naming the problem otherwise."""
    if Path(name).is_dir():
        if not is_sequence(name):
            raise ConfigError(f"{str(name)!r} is a folder but not a MOTChallenge sequence (no seqinfo.ini, det/det.txt "
                              "or gt/gt.txt in it)")
        return Path(name)
    return scenario.resolve(name)


class SourceSpec(str):
    """A source named once: what the user named, resolved (a shipped key, or the path of a .toml file or sequence
    folder; a str, so that records, journal keys and worker tasks stay strings) and read on its first `open`, which
    checks it. Each `open` makes a fresh source (every env its own, with its own obs_mode) from what was read: a
    sequence's files and a scenario's TOML are read once. Across processes it travels as the plain string, and each
    process reads it once again. `canonical`: the text is the name resolved (a shipped key as shipped)."""

    def __new__(cls, name: str | os.PathLike, canonical: bool = False) -> SourceSpec:
        found = resolve(name)
        self = super().__new__(cls, str(found) if canonical else str(name))
        self.recorded = isinstance(found, Path) and found.is_dir()
        self._read = None  # the sequence's Recording, or the scenario's (mapping, where), once read
        return self

    @classmethod
    def of(cls, what) -> SourceSpec:
        """`what` itself if it is one, else what it names."""
        return what if isinstance(what, SourceSpec) else cls(what)

    def __reduce__(self):
        return str, (str(self),)

    def open(self, overrides: Mapping | None = None) -> Scene | Recording:
        """A fresh source configured with `overrides`, as `open_source` opens it."""
        if self.recorded:
            from mtt_sim.sim.sensor import twin_sensor

            return _replayable(self._recording().configured(overrides, twin_sensor), self)
        from mtt_sim.sim.scene import Scene

        return Scene(self.scenario(overrides))

    def _recording(self) -> Recording:
        """The recorded sequence as read, once."""
        if self._read is None:
            from mtt_sim.real.sequence import Recording

            self._read = Recording(str(self))
        return self._read

    def length(self) -> int:
        """A recorded sequence's frames, whatever it would be replayed through (what it holds is not checked)."""
        return self._recording().length

    def scenario(self, overrides: Mapping | None = None) -> Scenario:
        """A named scenario's configuration with `overrides`, as `scenario.load` builds it (its TOML read once)."""
        if self._read is None:
            self._read = scenario.load_raw(str(self))
        return scenario.from_raw(copy.deepcopy(self._read[0]), self._read[1], overrides)


def open_source(what: str | os.PathLike | Scenario | SourceSpec, overrides: Mapping | None = None,
                benchmark: str | None = None, recorded: bool = False) -> Scene | Recording:
    """The source `what` names (`recorded`: it must be a sequence folder), configured with `overrides` (nested or
    dotted keys); `benchmark` (MOT15/16/17/20) sets a sequence's scoring rules instead of guessing them from its name
    and columns. A `SourceSpec` opens from what it has read."""
    if isinstance(what, SourceSpec) and benchmark is None and (what.recorded or not recorded):
        return what.open(overrides)
    # the sources are imported here, when one is opened: naming one (`resolve`) stays cheap for the command line
    if recorded or (not isinstance(what, Scenario) and is_sequence(what)):
        from mtt_sim.real.sequence import Recording
        from mtt_sim.sim.sensor import twin_sensor

        return _replayable(Recording(what, benchmark, overrides, twin_sensor), what)
    if benchmark is not None:
        raise ValueError(f"benchmark={benchmark!r} applies to recorded sequences, not to the scenario {what!r}")
    from mtt_sim.sim.scene import Scene

    return Scene(scenario.load(what, overrides))


def _replayable(recording: Recording, what) -> Recording:
    """The recording, if it has what its configuration replays: ground truth where it is scored, detection rows where
    they are replayed as recorded; a ConfigError saying what to do otherwise."""
    if recording.scored and not recording.truth_rows:
        raise ConfigError(f"{Path(what) / 'gt' / 'gt.txt'}: no rows: nothing to score against, and nobody for a "
                          "twin to detect (remove the file to replay the sequence unscored)")
    if recording.config.sensor.model == "recorded" and not recording.detection_rows:
        det = Path(what) / "det" / "det.txt"
        raise ConfigError(f"{det}: " + ("no detection rows" if det.is_file() else "not found")
                          + ": nothing to replay as the sequence's recorded detections; replay its ground truth "
                            "through the synthetic detector instead (--detector synthetic, sensor.model = "
                            "'synthetic')")
    return recording
