"""Which tuned parameter costs on real video: a tracker's defaults with one parameter at a time set to a tuned spec's.

Reads the rows of `tune_sim_to_real.py` (OUT.jsonl) and, for each chosen sequence, runs the tracker's defaults on the
real sequence with each parameter of the route's tuned spec alone, then prints the change in the metric against the
defaults. A parameter whose value alone loses most is the one the route got wrong (docs/tuning.md).

    python docs/experiments/one_parameter.py ../shared/data/mot15 OUT.jsonl --tracker gmphd --route generic \\
        --sequences ETH-Sunnyday,KITTI-17
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from mtt_sim.lab.experiment import run_episode


def one_at_a_time(folder: str, base: str, spec: str, metric: str = "HOTA") -> list[tuple[str, float]]:
    """(parameter=value, the metric of `base` with that parameter alone) for each parameter of the tuned `spec` that
    `base` (the tracker as tuned, e.g. lmb:reid=false) does not fix."""
    fixed = base.partition(":")[2].split(",")
    tuned = [p for p in spec.partition(":")[2].split(",") if p and p not in fixed]
    joiner = "," if ":" in base else ":"
    return [(p, run_episode(folder, f"{base}{joiner}{p}")["metrics"][metric]) for p in tuned]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data", help="the folder of the MOTChallenge sequences the rows were measured on")
    p.add_argument("rows", help="tune_sim_to_real.py's rows (one JSON object a line)")
    p.add_argument("--tracker", required=True, help="as in the rows, e.g. gmphd or lmb:reid=false")
    p.add_argument("--route", default="generic", help="whose tuned spec: oracle, twin, scene, generic, ...")
    p.add_argument("--sequences", default="", help="comma-separated names (default: every sequence in the rows)")
    p.add_argument("--metric", default="HOTA")
    args = p.parse_args()
    rows = [json.loads(line) for line in Path(args.rows).read_text().splitlines() if line.strip()]
    chosen = [r for r in rows if r["tracker"] == args.tracker and r["route"] == args.route
              and (not args.sequences or r["sequence"] in args.sequences.split(","))]
    if not chosen:
        raise SystemExit(f"{args.rows}: no row of tracker {args.tracker!r} on route {args.route!r}"
                         + (f" for {args.sequences}" if args.sequences else ""))
    for row in chosen:
        defaults, tuned = 100 * row["defaults"], 100 * row["real"]
        print(f"\n{row['sequence']}: {args.metric} defaults {defaults:.1f}, {args.route}-tuned {tuned:.1f}\n")
        print(f"| only | {args.metric} | change |\n|---|---:|---:|")
        folder = str(Path(args.data) / row["sequence"])
        for param, value in one_at_a_time(folder, row["tracker"], row["spec"], args.metric):
            print(f"| `{param}` | {100 * value:.1f} | {100 * value - defaults:+.1f} |", flush=True)


if __name__ == "__main__":
    main()
