"""The configuration tables both sources share: the detector (with its fitted presets), the Gym face and the
scoring; and `setting`, the field whose metadata documents and constrains a key.

Every field is a `setting`: its meaning, unit and allowed values live in its ``metadata``, which the validator
(`mtt_sim.core.validate`) checks and `mtt_sim.sim.scenario.reference_table` turns into the configuration reference.
A scenario (`mtt_sim.sim.config.Scenario`) and a recorded sequence (`mtt_sim.real.sequence.SequenceConfig`) hold them.
"""

from __future__ import annotations

import dataclasses
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from typing import Any


class ConfigError(ValueError):
    """A scenario file or override is invalid; the message names file, key, value and what is allowed."""


def setting(default, doc, unit="", lo=None, hi=None, choices=None):
    """A dataclass field whose metadata documents and constrains it."""
    meta = {"doc": doc, "unit": unit, "lo": lo, "hi": hi, "choices": choices}
    if isinstance(default, (list, tuple)) and default and dataclasses.is_dataclass(default[0]):
        return field(default_factory=lambda: tuple(default), metadata=meta)
    return field(default=default, metadata=meta)


def table(cls, doc):
    """A nested dataclass field (a TOML table)."""
    return field(default_factory=cls, metadata={"doc": doc})


def _fitted_detectors() -> dict[str, dict[str, Any]]:
    """The fitted detectors shipped as mtt_sim/core/detectors/<name>.toml, each a [sensor] table whose header says what it
    is fitted to; `model` and `memory` stay the scenario's own."""
    out = {}
    for entry in sorted(resources.files("mtt_sim.core").joinpath("detectors").iterdir(), key=lambda p: p.name):
        if entry.name.endswith(".toml"):
            table = tomllib.loads(entry.read_text())["sensor"]
            out[entry.name[:-5]] = {k: v for k, v in table.items() if k not in ("model", "memory")}
    return out


PRESETS: dict[str, dict[str, Any]] = {
    "ideal": dict(pd=1.0, min_visibility=0.0, box_noise=0.0, box_size_noise=0.0, box_drift=0.0, box_outlier_prob=0.0,
                  box_outlier_persist=0.0, box_scale=1.0, fragment_prob=0.0, merge_prob=0.0, clutter_rate=0.0,
                  site_rate=0.0, conf_true=0.95, conf_false=0.3),
    **_fitted_detectors(),
}


@dataclass(frozen=True)
class SensorConfig:
    """The simulated detector. Keys given explicitly override the chosen preset's values.

    `synthetic` detects a target with a probability logistic in its visible fraction and height, raised after a
    detection and lowered after a miss (`miss_corr`); boxes carry per-frame noise, occasional outliers and a per-target
    drift; false positives are fresh clutter plus persistent sites; confidences are Beta-distributed by source.
    """

    model: str = setting("synthetic", "synthetic: from the truth and the label map; foreground: background subtraction on "
                      "the frame; recorded: a sequence folder's det/det.txt (its default; synthetic replays its ground "
                      "truth through the synthetic detector instead)", choices=("synthetic", "foreground", "recorded"))
    preset: str = setting("", "fill the keys below from a detector preset (docs/detectors.md: what each is fitted to)",
                       choices=("",) + tuple(PRESETS))
    memory: bool = setting(True, "errors persist: misses follow each target's last outcome, boxes drift, false-positive "
                        "sites last site_life frames; false: every frame drawn independently with the same rates")
    pd: float = setting(0.95, "P(detect) of a fully visible target at least reference_height tall (its recall over time)", "",
                     0.0, 1.0)
    miss_corr: float = setting(0.5, "frame-to-frame correlation of a target's misses: P(detect) is P + (1 - P) miss_corr "
                            "after a detection and P (1 - miss_corr) after a miss", "", 0.0, 0.999)
    pd_spread: float = setting(0.0, "spread of each target's own ease of detection, drawn once: N(0, pd_spread) on the "
                            "logit of P(detect) (some people are found in almost every frame, some hardly ever)",
                            "logit", 0.0, 10.0)
    visibility_slope: float = setting(4.0, "logit of P(detect) gained per unit of visible fraction", "logit", 0.0, 100.0)
    height_slope: float = setting(0.0, "logit of P(detect) lost per halving of the box height below reference_height",
                               "logit", -10.0, 10.0)
    reference_height: float = setting(100.0, "box height from which pd holds (taller is no easier)", "px", 1.0, 1e4)
    min_visibility: float = setting(0.2, "never detected at or below this visible fraction", "", 0.0, 1.0)
    box_noise: float = setting(0.03, "per-frame noise of the box centre, across and down, in units of the box's scale "
                            "sqrt(w h) (standard deviation)", "", 0.0, 1.0)
    box_size_noise: float = setting(0.03, "per-frame noise of the box width and height, in units of sqrt(w h)", "",
                                 0.0, 1.0)
    box_drift: float = setting(0.0, "per-target drift of the box centre, AR(1) with this stationary standard deviation "
                            "(units of sqrt(w h)), on top of the per-frame noise", "", 0.0, 1.0)
    box_size_drift: float = setting(0.0, "the same for the box width and height", "", 0.0, 1.0)
    box_drift_corr: float = setting(0.9, "frame-to-frame correlation of the box drift", "", 0.0, 0.999)
    box_outlier_prob: float = setting(0.0, "probability a detection's box is an outlier (IoU 0.3-0.5 with its target's) "
                                   "when the target's last box was good", "", 0.0, 1.0)
    box_outlier_persist: float = setting(0.0, "the same when its last box was an outlier, or it was missed or new (poor "
                                      "boxes persist, and a target coming back is often boxed poorly)", "", 0.0, 1.0)
    box_outlier_noise: float = setting(0.3, "spread of outlier boxes and of sites held beside a target (units of "
                                    "sqrt(w h))", "", 0.01, 2.0)
    box_scale: float = setting(1.0, "systematic box enlargement (loose boxes > 1)", "", 0.5, 2.0)
    box_aspect: float = setting(1.0, "systematic widening relative to the height (> 1: boxes too wide)", "", 0.25, 4.0)
    fragment_prob: float = setting(0.02, "probability a visible target is reported as 2-3 fragments "
                                "(always when an occluder cuts it apart)", "", 0.0, 1.0)
    merge_prob: float = setting(0.5, "probability targets whose visible regions touch are reported as one box", "", 0.0, 1.0)
    clutter_rate: float = setting(0.5, "Poisson mean of fresh false detections per frame (each lasts one frame)", "1/frame",
                               0.0, 1000.0)
    site_rate: float = setting(0.0, "Poisson mean of persistent false-alarm sites born per frame", "1/frame", 0.0, 100.0)
    site_life: float = setting(10.0, "mean life of a site (geometric; it fires every frame it lives)", "frames", 1.0, 1e5)
    site_near: float = setting(0.5, "share of sites born beside a visible target (IoU 0.1-0.3 with it), moving with it "
                            "(double and partial boxes); the rest are static background boxes", "", 0.0, 1.0)
    conf_true: float = setting(0.85, "mean confidence of a detection of a fully visible target at least reference_height tall",
                            "", 0.01, 0.99)
    conf_visibility: float = setting(2.0, "logit of the mean true confidence gained per unit of visible fraction",
                                  "logit", 0.0, 100.0)
    conf_height: float = setting(0.0, "logit of the mean true confidence lost per halving of the box height below "
                              "reference_height", "logit", -10.0, 10.0)
    conf_outlier: float = setting(0.0, "logit of the mean confidence an outlier (a detection with a poor box) has beside "
                               "a good detection of the same target (real detectors score poor boxes lower)", "logit",
                               -20.0, 20.0)
    conf_false: float = setting(0.35, "mean confidence of a false detection", "", 0.01, 0.99)
    conf_spread: float = setting(8.0, "Beta concentration of the true confidences (higher = tighter)", "", 0.5, 1e4)
    conf_false_spread: float = setting(0.0, "Beta concentration of the false confidences (0 = conf_spread)", "", 0.0, 1e4)
    conf_offset: float = setting(0.0, "reported confidence = conf_offset + conf_scale * Beta draw (raw scores like DPM's)",
                              "", -1e4, 1e4)
    conf_scale: float = setting(1.0, "see conf_offset", "", 1e-6, 1e4)
    min_area: float = setting(20.0, "foreground: smallest blob kept", "px^2", 0.0, 1e6)
    threshold: float = setting(25.0, "foreground: grey-level difference that counts as foreground", "grey levels", 1.0, 255.0)
    learning_rate: float = setting(0.02, "foreground: background model update rate on background pixels", "", 0.0, 1.0)
    max_detections: int = setting(256, "observation rows; extra detections (lowest confidence first) are dropped", "", 1, 100000)


@dataclass(frozen=True)
class EnvConfig:
    """The Gym face: episode length, action size and what the observation holds."""

    max_steps: int = setting(300, "episode length; truncated after this many steps", "steps", 1, 10**7)
    max_tracks: int = setting(256, "rows of the action's padded track arrays", "", 1, 100000)
    obs_mode: str = setting("frame+detections", "detections: no frame in the observation (no rendering cost beyond the label map)",
                         choices=("frame+detections", "detections"))


@dataclass(frozen=True)
class ScoringConfig:
    """How tracks are scored against ground truth: the matching, the GOSPA parameters and the per-step reward."""

    similarity: str = setting("iou", "iou: box overlap; centroid: max(0, 1 - centre distance / zero_distance)",
                           choices=("iou", "centroid"))
    threshold: float = setting(0.5, "a track matches a target when their similarity is at least this (CLEAR, IDF1)", "", 0.01, 1.0)
    zero_distance: float = setting(20.0, "centroid similarity reaches 0 at this centre distance", "px", 0.1, 1e5)
    gospa_c: float = setting(50.0, "GOSPA cut-off distance (a miss or a false track costs c/2)", "px", 0.1, 1e5)
    gospa_p: float = setting(1.0, "GOSPA order", "", 1.0, 10.0)
    min_visibility: float = setting(0.0, "targets less visible than this are not scored (0 = every target in the image)", "", 0.0, 1.0)
    reward_mode: str = setting("mota", "mota: TP - FP - IDSW (return / GT boxes = MOTA); gospa: -GOSPA of the frame; "
                            "iou: iou_weight * summed IoU of matches - fp_weight * FP - fn_weight * FN",
                            choices=("mota", "gospa", "iou"))
    iou_weight: float = setting(1.0, "reward_mode iou: weight of the matched similarity", "", 0.0, 1e3)
    fp_weight: float = setting(1.0, "reward_mode iou: cost of a false track", "", 0.0, 1e3)
    fn_weight: float = setting(1.0, "reward_mode iou: cost of a missed target", "", 0.0, 1e3)
