"""What a missed track means, on real sequences and on the learned policy's training scenes.

Runs a policy (the shipped `learned` one unless --policy) over each sequence folder's detections and, against its
ground truth, counts two things:

- when a candidate is first missed, has its person left the ground truth (the view)? and if so, was the track within
  0.2 box heights of the image border (the `border` feature)?
- when a candidate missed for two frames or more is matched again, is the detection its own person's (IoU >= 0.5),
  another person's, or nobody's?

A policy that keeps missed tracks and reports them again at the first match pays where misses mean "gone" and late
matches are someone else (docs/learning.md).

    python docs/experiments/policy_misses.py ../shared/data/mot15/* OUT/mot17_like-dpm/*
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from mtt_sim.boxes import EPS, box_iou, match
from mtt_sim.real.sequence import Recording
from mtt_sim.trackers.learned import SHIPPED_POLICY, load_policy
from mtt_sim.trackers.parts.management import FEATURES, Candidates, decisions

BORDER = FEATURES.index("border")


def people_of(boxes: np.ndarray, truth) -> np.ndarray:
    """Each box's person (ground-truth id) by TrackEval's one-to-one match at IoU >= 0.5, -1 for none."""
    who = np.full(len(boxes), -1)
    if len(boxes) and len(truth):
        rows, cols = match(box_iou(boxes, truth.boxes), 0.5 - EPS)
        who[rows] = truth.ids[cols]
    return who


def misses(folder: str, weights: np.ndarray) -> dict[str, float]:
    """The counts above for one sequence folder."""
    rec = Recording(folder)
    candidates = Candidates((rec.info.width, rec.info.height))
    person: dict[int, int] = {}
    first = gone = gone_at_border = 0
    late = np.zeros(3, int)  # matches after two or more misses: own person, another, nobody
    for k in range(len(rec)):
        dets = rec.detections(k)
        tracks = candidates.tracks
        missed_before = dict(zip(tracks.ids.tolist(), tracks.misses.tolist()))
        features = candidates.propose(dets)
        truth = rec.truth(k)
        # a matched track's box is its filter's update by its detection: the detection it overlaps most
        matched = np.flatnonzero(tracks.misses == 0)
        if len(matched) and len(dets):
            took = box_iou(tracks.boxes()[matched], dets[:, :4]).argmax(axis=1)
            who = people_of(dets[:, :4], truth)[took]
            for track, p in zip(tracks.ids[matched].tolist(), who):
                if missed_before.get(track, 0) >= 2 and track in person:
                    late[0 if p == person[track] else 1 if p >= 0 else 2] += 1
                if p >= 0:
                    person[track] = p
        for i in np.flatnonzero(tracks.misses == 1):
            track = int(tracks.ids[i])
            if missed_before.get(track) == 0 and track in person:
                first += 1
                if person[track] not in truth.ids:
                    gone += 1
                    gone_at_border += features[i, BORDER] < 0.2
        candidates.decide(*decisions(weights, features))
    return {"first misses": first, "gone": gone / max(first, 1), "gone at the border": gone_at_border / max(gone, 1),
            "late matches": late.sum(), **dict(zip(("own", "another", "nobody"), late / max(late.sum(), 1)))}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("folders", nargs="+", help="sequence folders with ground truth (real, or exported replays)")
    p.add_argument("--policy", default=str(SHIPPED_POLICY), help="a policy file (default: the shipped one)")
    args = p.parse_args()
    weights = load_policy(args.policy)
    print("| sequence | first misses | person gone | of those, at the border | late matches | own | another | nobody |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for folder in args.folders:
        m = misses(folder, weights)
        name = "/".join(Path(folder).parts[-2:])
        print(f"| {name} | {m['first misses']} | {m['gone']:.2f} | {m['gone at the border']:.2f} | "
              f"{m['late matches']} | {m['own']:.2f} | {m['another']:.2f} | {m['nobody']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
