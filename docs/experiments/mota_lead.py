"""Where one tracker's MOTA lead over another comes from: paired differences over the seeds of a bench or sweep
records file (`--out x.csv`), split exactly into the parts from misses, false positives and identity switches.

MOTA = 1 - (FN + FP + IDSW) / GT for each episode, so on a seed both trackers ran, the lead of A over B is
(FN_B - FN_A) / GT + (FP_B - FP_A) / GT + (IDSW_B - IDSW_A) / GT. Each part is averaged over the seeds with its
95 % interval (Student's t), in MOTA points.

    python docs/experiments/mota_lead.py records.csv "lmb vs sort" "sort:min_hits=1,max_age=5 vs sort" ...
"""

import csv
import json
import sys
from collections import defaultdict

import numpy as np

from mtt_sim.experiment import mean_ci

PARTS = ("FN", "FP", "IDSW")


def episodes(path: str) -> dict:
    """{(tracker, column): {seed: row}}, the column a sweep's config or a bench's scenario."""
    cells = defaultdict(dict)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["error"]:
                continue
            config = json.loads(row["config"])
            column = ", ".join(f"{k.split('.')[-1]}={v}" for k, v in config.items()) or row["scenario"]
            cells[row["tracker"], column][int(row["seed"])] = row
    return cells


def lead(a: dict, b: dict) -> dict:
    """Mean and 95 % interval, in points, of A's MOTA lead over B and of its parts, over the seeds both ran."""
    seeds = sorted(a.keys() & b.keys())
    gt = np.array([float(a[s]["num_gt_dets"]) for s in seeds])
    out = {"MOTA": [100 * (float(a[s]["MOTA"]) - float(b[s]["MOTA"])) for s in seeds]}
    for part in PARTS:
        out[part] = list(100 * np.array([float(b[s][part]) - float(a[s][part]) for s in seeds]) / gt)
    return {k: mean_ci(v) for k, v in out.items()} | {"seeds": len(seeds)}


def main(path: str, pairs: list[str]) -> None:
    cells = episodes(path)
    columns = list(dict.fromkeys(column for _, column in cells))
    print("| lead (MOTA points, mean ± 95 % interval) | of | MOTA | from FN | from FP | from IDSW |")
    print("|---|---|---:|---:|---:|---:|")
    for pair in pairs:
        a, sep, b = pair.partition(" vs ")
        if not sep:
            raise SystemExit(f"{pair!r}: expected 'A vs B', two tracker specs of the records")
        for column in columns:
            if (a, column) not in cells or (b, column) not in cells:
                raise SystemExit(f"no records of {a!r} and {b!r} in {column}; trackers: "
                                 f"{', '.join(sorted({t for t, _ in cells}))}")
            d = lead(cells[a, column], cells[b, column])
            print(f"| `{a}` over `{b}` | {column} | " +
                  " | ".join(f"{d[k][0]:+.1f} ± {d[k][1]:.1f}" for k in ("MOTA", *PARTS)) + " |")


if __name__ == "__main__":
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2:])
