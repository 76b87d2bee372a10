"""How far a tracker tuned in simulation held on real video, per route: the record that `tune` and `advise` quote.

A spec can be tuned on the camera's own labelled frames (the oracle), on its twin (its real people through a synthetic
detector: a sequence folder with `sensor.model = "synthetic"`), on its label-free fitted scene (`mtt-sim fit-scene`)
or on a generic scenario. The last three are the simulated routes. `docs/experiments/tune_sim_to_real.py` tuned each
on the shared MOT15 sequences and scored the result on their real labels; RECORD holds what it measured (printed by
its `--record`), per route, for the fitted scene per kind of camera the fit found (a walking camera's scene held worse
than a still one's), and per tracker as well as pooled (a route that holds for SORT can fail a filter with a motion
model). `caution` turns a record into the line a user of a tracker should read before trusting the route.
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


# Measured by docs/experiments/tune_sim_to_real.py --record (docs/tuning.md, "Six trackers, four routes", "The twin
# with the boxes' jitter matched" and "The fitted scene with people who walk with the camera"): sort, bytetrack,
# ocsort, gmphd, lmb (reid=false) and jpda, 20 trials a study, on the eight shared MOT15 sequences. The twin and the
# scene with the detector `calibrate` fits now, leaving the sequence out; the scene as `fit-scene` fits it now
# (ETH-Bahnhof, ETH-Sunnyday and KITTI-13 go forward: walking cameras), its studies about 600 frames a trial as
# `advise` runs them ("About 600 frames a trial": the three shortest sequences, all still cameras, were tuned again).
RECORD: dict[tuple[str, str, str], Record] = {
    ("generic", "any", "any"): Record(sequences=8, pairs=48, gaining=42, share=-0.37, losing=28),
    ("generic", "any", "bytetrack"): Record(sequences=8, pairs=8, gaining=8, share=-0.15, losing=3),
    ("generic", "any", "gmphd"): Record(sequences=8, pairs=8, gaining=4, share=-2.9, losing=8),
    ("generic", "any", "jpda"): Record(sequences=8, pairs=8, gaining=7, share=-1.12, losing=7),
    ("generic", "any", "lmb"): Record(sequences=8, pairs=8, gaining=7, share=-6.33, losing=7),
    ("generic", "any", "ocsort"): Record(sequences=8, pairs=8, gaining=8, share=0.09, losing=2),
    ("generic", "any", "sort"): Record(sequences=8, pairs=8, gaining=8, share=0.31, losing=1),
    ("scene", "still", "any"): Record(sequences=5, pairs=30, gaining=24, share=0.46, losing=3),
    ("scene", "still", "bytetrack"): Record(sequences=5, pairs=5, gaining=5, share=0.66, losing=0),
    ("scene", "still", "gmphd"): Record(sequences=5, pairs=5, gaining=1, share=-0.2, losing=1),
    ("scene", "still", "jpda"): Record(sequences=5, pairs=5, gaining=4, share=0.33, losing=1),
    ("scene", "still", "lmb"): Record(sequences=5, pairs=5, gaining=4, share=-0.01, losing=1),
    ("scene", "still", "ocsort"): Record(sequences=5, pairs=5, gaining=5, share=0.51, losing=0),
    ("scene", "still", "sort"): Record(sequences=5, pairs=5, gaining=5, share=0.8, losing=0),
    ("scene", "walking", "any"): Record(sequences=3, pairs=18, gaining=18, share=0.6, losing=4),
    ("scene", "walking", "bytetrack"): Record(sequences=3, pairs=3, gaining=3, share=0.32, losing=0),
    ("scene", "walking", "gmphd"): Record(sequences=3, pairs=3, gaining=3, share=0.67, losing=1),
    ("scene", "walking", "jpda"): Record(sequences=3, pairs=3, gaining=3, share=0.51, losing=1),
    ("scene", "walking", "lmb"): Record(sequences=3, pairs=3, gaining=3, share=0.73, losing=0),
    ("scene", "walking", "ocsort"): Record(sequences=3, pairs=3, gaining=3, share=0.78, losing=1),
    ("scene", "walking", "sort"): Record(sequences=3, pairs=3, gaining=3, share=0.54, losing=1),
    ("twin", "any", "any"): Record(sequences=8, pairs=48, gaining=42, share=0.47, losing=5),
    ("twin", "any", "bytetrack"): Record(sequences=8, pairs=8, gaining=8, share=0.48, losing=0),
    ("twin", "any", "gmphd"): Record(sequences=8, pairs=8, gaining=4, share=0.69, losing=1),
    ("twin", "any", "jpda"): Record(sequences=8, pairs=8, gaining=7, share=0.33, losing=1),
    ("twin", "any", "lmb"): Record(sequences=8, pairs=8, gaining=7, share=0.58, losing=1),
    ("twin", "any", "ocsort"): Record(sequences=8, pairs=8, gaining=8, share=0.45, losing=1),
    ("twin", "any", "sort"): Record(sequences=8, pairs=8, gaining=8, share=0.62, losing=1),
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
    """The kind of camera of a fit-scene file's text, as its fit found it: "walking" where it moves (a common shift,
    or going forward), else "still"."""
    render = tomllib.loads(scene).get("render", {})
    return "walking" if render.get("camera") == "walking" or render.get("camera_forward", 0) > 0 else "still"


def caution(route: str, kind: str, tracker: str = ANY) -> str | None:
    """The line to show a user tuning `tracker` (a registered name) by `route` on a camera of `kind`, or None where
    the record says the route held: the tracker's own record, else the measured trackers' pooled one."""
    record, whose = RECORD.get((route, kind, tracker)), "specs" if tracker == ANY else f"{tracker} specs"
    if record is None and tracker != ANY:
        record, whose = RECORD.get((route, kind, ANY)), f"specs of the measured trackers ({tracker} was not measured)"
    where = "the shared sequences" if kind == ANY else f"the shared {kind} cameras"
    if record is None:
        return (f"tuning on {NAMES[route]} has not been measured against real labels on {where}: check the tuned spec "
                "on a few labelled frames where you can")
    if record.trusted:
        return None
    kept = ":" if record.share is None else (f" kept a median {record.share:.2f} of the gain found by tuning on real "
                                             "labels, and")
    return (f"on {where} ({record.sequences} MOT15 sequences), {whose} tuned on {NAMES[route]}{kept} {record.losing} "
            f"of {record.pairs} lost more than a point of HOTA against the defaults on real (docs/tuning.md): "
            + ("the defaults did better there; prefer them unless a few labelled frames say otherwise"
               if record.share is not None and record.share < 0 else
               "check the tuned spec on a few labelled frames where you can"))


def records(rows: Iterable[dict], kinds: Mapping[str, str]) -> dict[tuple[str, str, str], Record]:
    """RECORD from tune_sim_to_real's rows (sequence, tracker spec, route, defaults, real), with `kinds` the camera
    kind fit-scene found for each sequence: the twin and generic routes over all sequences, the scene per kind; each
    per tracker (its registered name) and over every tracker (ANY). Routes other than NAMES' are left out."""
    from mtt_sim.trackers import TrackerSpec

    rows = list(rows)
    oracle = {(r["sequence"], r["tracker"]): r["real"] - r["defaults"] for r in rows if r["route"] == "oracle"}
    grouped: dict[tuple[str, str, str], list[dict]] = {}
    for r in rows:
        if r["route"] in NAMES:
            kind = kinds[r["sequence"]] if r["route"] == "scene" else ANY
            for tracker in (ANY, TrackerSpec.of(r["tracker"]).registered):
                grouped.setdefault((r["route"], kind, tracker), []).append(r)
    out = {}
    for key, group in sorted(grouped.items()):
        gains = [(r["real"] - r["defaults"], oracle.get((r["sequence"], r["tracker"]))) for r in group]
        shares = [g / o for g, o in gains if o is not None and o >= 0.01]
        out[key] = Record(sequences=len({r["sequence"] for r in group}), pairs=len(group), gaining=len(shares),
                          share=round(statistics.median(shares), 2) if shares else None,
                          losing=sum(g < -0.01 for g, _ in gains))
    return out
