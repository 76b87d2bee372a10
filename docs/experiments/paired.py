"""Paired differences between trackers over the seeds of a bench or sweep records file (`--out x.csv` or `.json`):
per column (scenario or swept value), the mean of a metric's difference, A minus B, over the seeds where both have a
value, with its 95 % interval (Student's t). Pairing removes what the seeds share (the scene's difficulty), so it
tells apart differences that the trackers' own intervals overlap.

For MOTA the difference is in points and split exactly into its parts from misses, false positives and identity
switches: MOTA = 1 - (FN + FP + IDSW) / GT on each seed, so A's lead over B is (FN_B - FN_A) / GT +
(FP_B - FP_A) / GT + (IDSW_B - IDSW_A) / GT.

    python docs/experiments/paired.py records.csv MOTA "lmb vs sort" "sort:min_hits=1,max_age=5 vs sort"
    python docs/experiments/paired.py records.json HiddenCentreError "ipf vs ipf:interactive=false"
"""

import csv
import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from mtt_sim.lab.experiment import METRICS, mean_ci

PARTS = ("FN", "FP", "IDSW")


def _metrics(record: dict) -> dict:
    """A record's metrics as floats (None where an episode has no value), from a CSV row or a JSON record."""
    values = record["metrics"] if "metrics" in record else record
    return {k: None if values.get(k) in ("", None) else float(values[k]) for k in METRICS}


def episodes(path: str) -> dict:
    """{(tracker, column): {seed: metrics}}, the column a sweep's config or a bench's scenario; failed ones left out."""
    with open(path, newline="") as f:
        records = json.load(f) if Path(path).suffix == ".json" else list(csv.DictReader(f))
    cells = defaultdict(dict)
    for r in records:
        if r["error"]:
            continue
        config = r["config"] if isinstance(r["config"], dict) else json.loads(r["config"])
        scenario = Path(r["scenario"])
        column = ", ".join(f"{k.split('.')[-1]}={v}" for k, v in config.items()) or \
            (scenario.stem if scenario.suffix == ".toml" else scenario.name)
        cells[r["tracker"], column][int(r["seed"])] = _metrics(r)
    return cells


def difference(a: dict, b: dict, metric: str) -> dict:
    """Mean and 95 % interval of A's metric minus B's over the seeds where both have a value (MOTA in points, with
    its parts), and how many seeds that is."""
    seeds = sorted(s for s in a.keys() & b.keys() if a[s].get(metric) is not None and b[s].get(metric) is not None)
    if metric != "MOTA":
        return {metric: mean_ci([a[s][metric] - b[s][metric] for s in seeds]), "seeds": len(seeds)}
    gt = np.array([a[s]["num_gt_dets"] for s in seeds])
    out = {"MOTA": mean_ci([100 * (a[s]["MOTA"] - b[s]["MOTA"]) for s in seeds])}
    for part in PARTS:
        out[part] = mean_ci(100 * np.array([b[s][part] - a[s][part] for s in seeds]) / gt)
    return out | {"seeds": len(seeds)}


def main(path: str, metric: str, pairs: list[str]) -> None:
    cells = episodes(path)
    columns = list(dict.fromkeys(column for _, column in cells))
    keys = (metric, *PARTS) if metric == "MOTA" else (metric,)
    head = ["MOTA points", "from FN", "from FP", "from IDSW"] if metric == "MOTA" else [metric]
    values = [m[metric] for cell in cells.values() for m in cell.values() if m.get(metric) is not None]
    digits = 1 if metric == "MOTA" or max(map(abs, values), default=0) > 1 else 3  # points, pixels, counts: 1
    print(f"| A minus B (mean ± 95 % interval, paired by seed) | of | {' | '.join(head)} | seeds |")
    print("|---|---|" + "---:|" * (len(keys) + 1))
    for pair in pairs:
        a, sep, b = pair.partition(" vs ")
        if not sep:
            raise SystemExit(f"{pair!r}: expected 'A vs B', two tracker specs of the records")
        for column in columns:
            if (a, column) not in cells or (b, column) not in cells:
                raise SystemExit(f"no records of {a!r} and {b!r} in {column}; trackers: "
                                 f"{', '.join(sorted({t for t, _ in cells}))}")
            d = difference(cells[a, column], cells[b, column], metric)
            text = " | ".join(f"{d[k][0]:+.{digits}f} ± {d[k][1]:.{digits}f}" for k in keys)
            print(f"| `{a}` minus `{b}` | {column} | {text} | {d['seeds']} |")


if __name__ == "__main__":
    if len(sys.argv) < 4:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3:])
