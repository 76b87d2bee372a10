"""The published baselines' tracker time against Roboflow's same trackers on real detections: `mtt-sim perf`'s
baselines table on each MOTChallenge sequence folder of DATA (needs the [peers] extra for the Roboflow column).

    python docs/experiments/peer_speed.py ../shared/data/mot15 --repeats 5
"""

import argparse
from pathlib import Path

from mtt_sim.lab import perf


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data", help="a folder of MOTChallenge sequence folders")
    p.add_argument("--repeats", type=int, default=5)
    args = p.parse_args()
    folders = sorted(f for f in Path(args.data).iterdir() if (f / "det" / "det.txt").is_file())
    rows = perf.measure_baselines(args.repeats, 10**6, [(str(f), {}) for f in folders])
    print(perf.report_baselines(rows))
    for tracker in perf.BASELINE_PEERS:
        mine = [r for r in rows if r["tracker"] == tracker]
        ours, theirs = (sum(r["fps"] ** -1 for r in mine), sum(r["roboflow_fps"] ** -1 for r in mine))
        print(f"{tracker}: ours {len(mine) / ours:.0f} frames/s, Roboflow's {len(mine) / theirs:.0f} "
              "(harmonic means over the sequences)")


if __name__ == "__main__":
    main()
