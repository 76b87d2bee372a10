"""Sim-to-real tuning, measured: for each MOTChallenge sequence and tracker, tune on (a) the sequence itself (the
oracle) and (b) its twin (its ground-truth people through a detector fitted on the other sequences), then score
both results and the defaults on the real sequence. Prints a Markdown table: the real gain over the defaults of each
way and the share of the oracle's gain the twin recovers; writes every row to OUT.json.

    python docs/experiments/tune_sim_to_real.py ../shared/data/mot15 OUT.json --trackers sort,bytetrack --trials 30
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path

from mtt_sim.lab.experiment import run_episode
from mtt_sim.lab.tune import tune
from mtt_sim.sim2real.calibrate import calibrate, to_toml


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data", help="a folder of MOTChallenge sequence folders")
    p.add_argument("out", help="the rows as JSON")
    p.add_argument("--trackers", default="sort,bytetrack")
    p.add_argument("--metric", default="HOTA")
    p.add_argument("--trials", type=int, default=30)
    p.add_argument("--seeds", type=int, default=2, help="twin episodes per trial")
    args = p.parse_args()
    folders = sorted(f for f in Path(args.data).iterdir() if (f / "gt" / "gt.txt").is_file())
    work = Path(args.out).with_suffix("")
    work.mkdir(parents=True, exist_ok=True)
    rows = []
    for folder in folders:
        fitted = work / f"fitted_without_{folder.name}.toml"
        if not fitted.is_file():
            fitted.write_text(to_toml(calibrate([f for f in folders if f != folder], seeds=1)))
        twin = {"sensor.model": "synthetic", **{f"sensor.{k}": v for k, v in _sensor(fitted).items()}}
        for spec in args.trackers.split(","):
            oracle = tune(spec, [str(folder)], args.metric, args.trials)[0]
            by_twin = tune(spec, [str(folder)], args.metric, args.trials, seeds=range(args.seeds), config=twin)[0]
            real = run_episode(str(folder), by_twin.spec)["metrics"][args.metric]
            rows.append({"sequence": folder.name, "tracker": spec, "defaults": oracle.default_value,
                         "oracle": oracle.value, "twin": real, "twin_spec": by_twin.spec, "oracle_spec": oracle.spec})
            print(json.dumps(rows[-1]), flush=True)
    Path(args.out).write_text(json.dumps(rows, indent=1))
    print(table(rows, args.metric))


def _sensor(path: Path) -> dict:
    import tomllib

    return tomllib.loads(path.read_text())["sensor"]


def table(rows: list[dict], metric: str) -> str:
    """Per tracker and sequence: the defaults' score, the oracle's and the twin-tuned spec's gains (points), and the
    share of the oracle's gain the twin recovers (where the oracle gains at least a point); medians at the end."""
    lines = [f"| tracker | sequence | {metric} defaults | oracle gain | twin gain | twin / oracle |", "|---|---|---:|---:|---:|---:|"]
    shares = {}
    for r in rows:
        gain, twin = 100 * (r["oracle"] - r["defaults"]), 100 * (r["twin"] - r["defaults"])
        share = twin / gain if gain >= 1 else None
        if share is not None:
            shares.setdefault(r["tracker"], []).append(share)
        lines.append(f"| {r['tracker']} | {r['sequence']} | {100 * r['defaults']:.1f} | {gain:+.1f} | {twin:+.1f} | "
                     + (f"{share:.2f}" if share is not None else "-") + " |")
    lines += ["", *(f"{t}: median share of the oracle's gain recovered {statistics.median(s):.2f} ({len(s)} sequences "
                    "where the oracle gains at least a point)" for t, s in shares.items())]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
