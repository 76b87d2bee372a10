"""The learned tracker: a base tracker's candidates (`management.Candidates`: SORT's or ByteTrack's association) with a
learned linear policy deciding which to report and which to keep, in place of the base's rules (SORT's min_hits and
max_age). `mtt-sim learn-policy` trains the policy."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np

from .base import Param, Tracker, Tracks, detections
from .parts.management import BASES, FEATURES, SORT_RULES, Candidates, decisions

SHIPPED_POLICY = Path(__file__).with_name("data") / "policy_sort.npz"


def load_policy(path: str | Path) -> np.ndarray:
    """The (2, len(FEATURES) + 1) weights of a policy file written by `save_policy`, or a ValueError naming the file
    and what it lacks."""
    path = Path(path)
    if path.name == "sort_rules":
        return SORT_RULES.copy()
    try:
        with np.load(path, allow_pickle=False) as data:
            weights, names = data["weights"], tuple(str(n) for n in data["features"])
    except (OSError, ValueError, KeyError) as err:
        raise ValueError(f"policy file {path}: not a policy written by mtt-sim learn-policy ({err})") from None
    if names != FEATURES or weights.shape != SORT_RULES.shape or not np.isfinite(weights).all():
        raise ValueError(f"policy file {path}: weights {weights.shape} over features {names}: expected finite weights "
                         f"{SORT_RULES.shape} over {FEATURES}")
    return weights


def save_policy(path: str | Path, weights: np.ndarray, **about: str) -> None:
    """Write a policy: its weights, the feature names they read, and `about` (what it was trained on, how), as an
    .npz file that np.load reads. Written member by member with a fixed date (np.savez stamps the time of writing),
    so that the same policy is the same bytes."""
    arrays = {"weights": np.asarray(weights, float), "features": np.array(FEATURES),
              **{k: np.array(v) for k, v in about.items()}}
    with zipfile.ZipFile(path, "w") as archive:
        for name, array in arrays.items():
            member = io.BytesIO()
            np.lib.format.write_array(member, array, allow_pickle=False)
            archive.writestr(zipfile.ZipInfo(f"{name}.npy", date_time=(1980, 1, 1, 0, 0, 0)), member.getvalue())


class Learned(Tracker):
    """Track management learned from the reward: each frame the base's association (SORT's, or ByteTrack's with its
    low-confidence round) proposes candidates, and a linear policy over their features (`management.FEATURES`)
    decides to report each and to keep it. `policy=sort_rules` is SORT's own rules (min_hits=3, max_age=1) in that
    form: with base=sort the tracker then equals SORT box for box. The shipped policy was trained with base=sort."""

    name = "learned"
    description = "SORT's candidates with a learned report / keep policy (Xiang et al. 2015's decisions, by CMA-ES)"
    parameters = {
        "policy": Param("", None, "a policy file from mtt-sim learn-policy; '' the shipped one, sort_rules SORT's rules"),
        "base": Param("sort", BASES, "the tracker whose association proposes the candidates"),
        "iou_threshold": Param(0.3, "[0, 1]", "least IoU of a match"),
    }

    def __init__(self, **params):
        super().__init__(**params)
        self.weights = load_policy(self.params["policy"] or SHIPPED_POLICY)

    def reset(self, info=None):
        size = (info or {}).get("image_size", (1920, 1080))
        self.candidates = Candidates(tuple(size), self.params["iou_threshold"], base=self.params["base"])

    def update(self, obs) -> Tracks:
        features = self.candidates.propose(detections(obs))
        ids, boxes = self.candidates.decide(*decisions(self.weights, features))
        return Tracks.of(ids, boxes)
