"""`mtt-sim check-real DATA`: the project held against real data (the shared folder's layout, see its README).

1. Baselines as published: `sort`, `bytetrack` and `ocsort` run through the env on each `DATA/mot15/<SEQ>` and must give,
   box for box and id for id, what the reference code gave (`DATA/reference/<tracker>/<SEQ>.txt`, written with 6
   decimals, so boxes agree to half a unit of the sixth: 5e-7).
2. Scoring as TrackEval: the env's metrics of those runs must be the published figures (the SORT README's table,
   and what TrackEval gives on the reference outputs), the results files scored by `mtt-sim eval` must give the env's
   metrics exactly, and a published tracker's MOT17 results must score as TrackEval scores them (MOT17's distractor
   classes and zero-marked rows included).
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from mtt_sim.lab.experiment import run_episode
from mtt_sim.real.motchallenge import evaluate_results
from mtt_sim.real.sequence import read_rows

TOLERANCE = 5e-7 + 1e-9  # the reference files' 6 decimals
# MOTA (%), FP, FN, IDSW of the reference outputs under TrackEval: the SORT README's "Main Results" for TUD-Campus,
# ETH-Sunnyday and KITTI-17, and for the others what DATA/README.md reports
SORT = {"TUD-Campus": (62.7, 15, 113, 6), "ETH-Sunnyday": (59.1, 319, 418, 22), "KITTI-17": (60.2, 38, 225, 9),
        "ADL-Rundle-6": (38.1, 898, 2128, 75), "KITTI-13": (19.3, 131, 468, 16), "PETS09-S2L1": (61.9, 484, 1118, 103),
        "ETH-Bahnhof": (44.6, 1024, 1903, 71)}
# MOTA, IDF1 (%) of ByteTrack's reference outputs under TrackEval (DATA/README.md)
BYTETRACK = {"TUD-Campus": (59.6, 67.9), "ETH-Sunnyday": (57.9, 74.5), "KITTI-17": (57.1, 67.2),
             "ADL-Rundle-6": (36.7, 43.3), "KITTI-13": (4.3, 41.0), "PETS09-S2L1": (63.2, 44.9),
             "TUD-Stadtmitte": (69.9, 71.0), "ETH-Bahnhof": (37.1, 54.3)}
# MOTA, IDF1, HOTA (%) of OC-SORT's reference outputs under TrackEval (DATA/README.md)
OCSORT = {"ADL-Rundle-6": (36.8, 44.1, 32.0), "ETH-Bahnhof": (42.2, 56.0, 41.0), "ETH-Sunnyday": (56.7, 73.2, 52.9),
          "KITTI-13": (17.5, 41.0, 26.2), "KITTI-17": (58.3, 75.0, 46.4), "PETS09-S2L1": (57.0, 46.7, 35.2),
          "TUD-Campus": (58.8, 69.2, 49.9), "TUD-Stadtmitte": (69.6, 73.9, 51.6)}
# TrackEval (MotChallenge2DBox, MOT17) on Lif_T's published results (DATA/README.md)
MOT17 = {"MOT17-02-DPM": {"MOTA": 0.404661, "IDF1": 0.502828, "HOTA": 0.449662, "TP": 7564, "FP": 19, "FN": 11017,
                          "IDSW": 26},
         "MOT17-09-FRCNN": {"MOTA": 0.715493, "IDF1": 0.728845, "HOTA": 0.642261, "TP": 3874, "FP": 54, "FN": 1451,
                            "IDSW": 10}}


def compare_tracks(ours: np.ndarray, reference: np.ndarray) -> str | None:
    """None if two results files' rows (frame, id, x, y, w, h, ...) hold the same tracks, ids included, boxes within
    TOLERANCE; else what differs first."""
    if len(ours) != len(reference):
        return f"{len(ours)} rows against the reference's {len(reference)}"
    a, b = (r[np.lexsort((r[:, 1], r[:, 0]))][:, :6] for r in (ours, reference))
    differs = (a[:, :2] != b[:, :2]).any(axis=1) | (np.abs(a[:, 2:] - b[:, 2:]) > TOLERANCE).any(axis=1)
    if differs.any():
        k = int(np.flatnonzero(differs)[0])
        return f"frame {a[k, 0]:g}: ours {a[k, 1:].tolist()}, the reference's {b[k, 1:].tolist()}"
    return None


def check(data: str | Path, out=print) -> bool:
    """Run every check, `out` a line per check; True when all pass."""
    data, passed = Path(data), []

    def report(ok: bool, text: str):
        passed.append(ok)
        out(f"{'ok  ' if ok else 'FAIL'} {text}")

    with tempfile.TemporaryDirectory() as tmp:
        for tracker in ("sort", "bytetrack", "ocsort"):
            for folder in sorted(p for p in (data / "mot15").iterdir() if p.is_dir()):
                seq, results = folder.name, Path(tmp) / f"{tracker}-{folder.name}.txt"
                record = run_episode(str(folder), tracker, results=str(results))
                m = record["metrics"]
                problem = compare_tracks(read_rows(results, 6), read_rows(data / "reference" / tracker / f"{seq}.txt", 6))
                report(problem is None, f"{tracker} {seq}: box for box the reference's output"
                       + (f" ({problem})" if problem else f" ({m['num_tracker_dets']} boxes)"))
                report(evaluate_results(folder, results) == m, f"{tracker} {seq}: its results file scores as the env")
                ours = (round(100 * m["MOTA"], 1), m["FP"], m["FN"], m["IDSW"])
                if tracker == "sort" and seq in SORT:
                    report(ours == SORT[seq], f"sort {seq}: MOTA, FP, FN, IDSW {ours}, published {SORT[seq]}")
                if tracker == "bytetrack" and seq in BYTETRACK:
                    got = (round(100 * m["MOTA"], 1), round(100 * m["IDF1"], 1))
                    report(got == BYTETRACK[seq], f"bytetrack {seq}: MOTA, IDF1 {got}, TrackEval {BYTETRACK[seq]}")
                if tracker == "ocsort" and seq in OCSORT:
                    got = tuple(round(100 * m[k], 1) for k in ("MOTA", "IDF1", "HOTA"))
                    report(got == OCSORT[seq], f"ocsort {seq}: MOTA, IDF1, HOTA {got}, TrackEval {OCSORT[seq]}")
    for seq, expected in MOT17.items():
        m = evaluate_results(data / "mot17" / seq, data / "mot17_results" / "LifT" / f"{seq}.txt")
        got = {k: round(m[k], 6) if isinstance(v, float) else m[k] for k, v in expected.items()}
        report(got == expected, f"Lif_T {seq} (MOT17 rules): {got}" + ("" if got == expected else f", TrackEval {expected}"))
    return all(passed)
