"""How far a tracker tuned in simulation held on real video, per route: the record that `tune` and `advise` quote.

A spec can be tuned on the camera's own labelled frames (the oracle), on its twin (its real people through a synthetic
detector: a sequence folder with `sensor.model = "synthetic"`), on its label-free fitted scene (`mtt-sim fit-scene`)
or on a generic scenario. The last three are the simulated routes. `docs/experiments/tune_sim_to_real.py` tuned each
on the shared MOT15 sequences and scored the result on their real labels; RECORD holds what it measured (printed by
its `--record`), per route and, for the fitted scene, per kind of camera the fit found, for a walking camera's scene
held worse than a still one's. `caution` turns a record into the line a user should read before trusting the route.
"""

from __future__ import annotations

import statistics
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Mapping

FITTED_HEADER = "# mtt-sim fit-scene"  # the first line of every scene file fit-scene writes
ANY = "any"  # the camera kind of a route recorded over all cameras
NAMES = {"twin": "the sequence's twin", "scene": "the camera's fitted scene", "generic": "a generic scenario"}


@dataclass(frozen=True)
class Record:
    """A route on real sequences: how many sequences and tuned (sequence, tracker) pairs, the median share of the
    real-labels gain it recovered (over the pairs where tuning on the labels gained a point or more: `gaining`), and
    how many of the pairs lost more than a point against the defaults on real."""

    sequences: int
    pairs: int
    gaining: int
    share: float | None  # None where no pair gained a point on the labels
    losing: int

    @property
    def trusted(self) -> bool:
        """Held on real video: a median share of at least half the gain and no pair losing more than a point."""
        return (self.share is None or self.share >= 0.5) and self.losing == 0


# Measured by docs/experiments/tune_sim_to_real.py --record (docs/tuning.md, "The four routes on the walking world"
# and after): sort, bytetrack, ocsort and gmphd, 20 trials a study, on the eight shared MOT15 sequences, the twin and
# the scene with the detector `calibrate` fits (confidences by maximum likelihood, outliers scored lower), the scenes
# as `fit-scene` fits them now.
RECORD: dict[tuple[str, str], Record] = {
    ("generic", "any"): Record(sequences=8, pairs=32, gaining=28, share=0.03, losing=14),
    ("scene", "still"): Record(sequences=6, pairs=24, gaining=20, share=0.5, losing=5),
    ("scene", "walking"): Record(sequences=2, pairs=8, gaining=8, share=-0.13, losing=3),
    ("twin", "any"): Record(sequences=8, pairs=32, gaining=28, share=0.36, losing=4),
}


def route_of(source: str, overrides: Mapping[str, object] | None = None) -> tuple[str, str] | None:
    """The simulated route that tuning on `source` (with episode `overrides`) takes, and its camera kind: ("twin",
    ANY) for a sequence folder through the synthetic detector, ("scene", "walking" or "still") for a fit-scene file,
    ("generic", ANY) for any other scenario; None for a sequence's own labels (nothing simulated)."""
    overrides = overrides or {}
    path = Path(source)
    if path.is_dir():
        return ("twin", ANY) if overrides.get("sensor.model") == "synthetic" else None
    if path.suffix == ".toml" and path.is_file():
        text = path.read_text()
        if text.startswith(FITTED_HEADER):
            return "scene", camera_kind(text)
    return "generic", ANY


def camera_kind(scene: str) -> str:
    """The kind of camera ("walking" or "still") of a fit-scene file's text: what its fit found."""
    return "walking" if tomllib.loads(scene).get("render", {}).get("camera") == "walking" else "still"


def caution(route: str, kind: str) -> str | None:
    """The line to show a user of `route` on a camera of `kind`, or None where the record says the route held."""
    record = RECORD.get((route, kind))
    where = "the shared sequences" if kind == ANY else f"the shared {kind} cameras"
    if record is None:
        return (f"tuning on {NAMES[route]} has not been measured against real labels on {where}: check the tuned spec "
                "on a few labelled frames where you can")
    if record.trusted:
        return None
    kept = ":" if record.share is None else (f" kept a median {record.share:.2f} of the gain found by tuning on real "
                                             "labels, and")
    return (f"on {where} ({record.sequences} MOT15 sequences), specs tuned on {NAMES[route]}{kept} {record.losing} of "
            f"{record.pairs} lost more than a point of HOTA against the defaults on real (docs/tuning.md): "
            + ("the defaults did better there; prefer them unless a few labelled frames say otherwise"
               if record.share is not None and record.share < 0 else
               "check the tuned spec on a few labelled frames where you can"))


def records(rows: Iterable[dict], kinds: Mapping[str, str]) -> dict[tuple[str, str], Record]:
    """RECORD from tune_sim_to_real's rows (sequence, tracker, route, defaults, real), with `kinds` the camera kind
    fit-scene found for each sequence: the twin and generic routes over all sequences, the scene per kind."""
    rows = list(rows)
    oracle = {(r["sequence"], r["tracker"]): r["real"] - r["defaults"] for r in rows if r["route"] == "oracle"}
    grouped: dict[tuple[str, str], list[dict]] = {}
    for r in rows:
        if r["route"] != "oracle":
            kind = kinds[r["sequence"]] if r["route"] == "scene" else ANY
            grouped.setdefault((r["route"], kind), []).append(r)
    out = {}
    for key, group in sorted(grouped.items()):
        gains = [(r["real"] - r["defaults"], oracle.get((r["sequence"], r["tracker"]))) for r in group]
        shares = [g / o for g, o in gains if o is not None and o >= 0.01]
        out[key] = Record(sequences=len({r["sequence"] for r in group}), pairs=len(group), gaining=len(shares),
                          share=round(statistics.median(shares), 2) if shares else None,
                          losing=sum(g < -0.01 for g, _ in gains))
    return out
