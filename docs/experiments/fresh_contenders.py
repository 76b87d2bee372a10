"""Does keeping the best of a study's best trials on fresh seeds pick specs that hold on real video?

For each row of a simulated route (`--route`: the fitted scene, or the twin) in `tune_sim_to_real.py`'s rows file (its
studies are seeded, so each is rerun as it was), the study's CONTENDERS best trials are scored on FRESH seeds 100-103
of its source and on the real sequence; then the route's figures (median share of the oracle's gain, losses of over
a point, the picks) are printed three ways: the study's best (as before `tune --confirm`), the contender best on the
fresh seeds (as `tune --confirm` keeps), and that or the defaults, whichever scores best on the fresh seeds (which
needs the rows' "confirmed_defaults", from `tune_sim_to_real.py --confirm 4`). A sequence's pick is the tracker whose
kept spec scores best on the fresh seeds.

    python docs/experiments/fresh_contenders.py ../shared/data/mot15 rows.jsonl OUT.jsonl --trackers sort,ocsort
    python docs/experiments/fresh_contenders.py ../shared/data/mot15 rows.jsonl TWIN.jsonl --route twin
    python docs/experiments/fresh_contenders.py ../shared/data/mot15 rows.jsonl OUT.jsonl --table
"""

from __future__ import annotations

import argparse
import json
import statistics
from pathlib import Path

from mtt_sim.lab.confirm import CONTENDERS
from mtt_sim.lab.experiment import run_episode
from mtt_sim.lab.tune import contenders_of, tune
from tune_sim_to_real import FRESH as FIRST_FRESH  # beside this file, as the routes' sources and real scoring
from tune_sim_to_real import real_score, source_of

FRESH = range(FIRST_FRESH, FIRST_FRESH + 4)  # the seeds tune_sim_to_real.py --confirm 4 scores the rows on


def contenders(data: Path, row: dict, work: Path) -> list[dict]:
    """The row's study rerun (`work`: tune_sim_to_real's folder of scenes and detectors); its contenders' study
    scores, mean HOTA on the FRESH seeds of its source, and real HOTA."""
    source, config = source_of(row["route"], data / row["sequence"], work)
    result, study = tune(row["tracker"], [source], "HOTA", row["trials"], range(row["seeds"]), config)
    if result.spec != row["spec"]:
        raise RuntimeError(f"{row['sequence']} {row['tracker']}: the rerun study found {result.spec}, not "
                           f"{row['spec']}")
    out = []
    for t in contenders_of(study, result, result.goals):
        spec = t.user_attrs["spec"]
        out.append({"spec": spec, "value": t.values[0],
                    "fresh": statistics.mean(run_episode(source, spec, s, config)["metrics"]["HOTA"] for s in FRESH),
                    "real": real_score(data / row["sequence"], spec, "HOTA")})
    return out


def chosen(row: dict, top: list[dict], how: str) -> tuple[float, float]:
    """The real and fresh score of the spec `how` keeps: "study" (its best), "fresh" (the contender best on the fresh
    seeds) or "fresh or defaults"."""
    pick = top[0] if how == "study" else max(top, key=lambda c: c["fresh"])  # max keeps the earlier on a tie
    if how == "fresh or defaults" and row["confirmed_defaults"] >= pick["fresh"]:
        return row["defaults"], row["confirmed_defaults"]
    return pick["real"], pick["fresh"]


def table(rows: list[dict], tops: dict, route: str = "scene") -> str:
    """The route's figures each way (see the module's docstring)."""
    oracle = {(r["sequence"], r["tracker"]): r for r in rows if r["route"] == "oracle"}
    tuned = {(r["sequence"], r["tracker"]): r for r in rows if r["route"] == route and
             (r["sequence"], r["tracker"]) in tops}
    lines = ["| kept | median share | losses of over a point | picks within 2 points | median gap | largest gap |",
             "|---|---:|---:|---:|---:|---:|"]
    for how in ("study", "fresh", "fresh or defaults"):
        got = {k: chosen(r, tops[k], how) for k, r in tuned.items()}
        gains = {k: 100 * (got[k][0] - r["defaults"]) for k, r in tuned.items()}
        best = {k: 100 * (oracle[k]["real"] - r["defaults"]) for k, r in tuned.items()}
        shares = [gains[k] / best[k] for k in tuned if best[k] >= 1]
        gaps = []
        for s in sorted({k[0] for k in tuned}):
            mine = [k for k in tuned if k[0] == s]
            top = max(mine, key=lambda k: got[k][1])
            gaps.append(100 * (max(oracle[k]["real"] for k in mine) - got[top][0]))
        lines.append(f"| {how} | {statistics.median(shares):.2f} | {sum(g < -1 for g in gains.values())} of "
                     f"{len(gains)} | {sum(g <= 2 for g in gaps)} of {len(gaps)} | {statistics.median(gaps):.1f} | "
                     f"{max(gaps):.1f} |")
    return "\n".join(lines)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data", help="a folder of MOTChallenge sequence folders")
    p.add_argument("rows", help="tune_sim_to_real.py's rows file (its scenes and detectors in the folder of the "
                                "same name)")
    p.add_argument("out", help="the contenders, one JSON object a study (a rerun skips those there)")
    p.add_argument("--route", default="scene", choices=("scene", "twin"), help="the simulated route's rows")
    p.add_argument("--trackers", default="", help="only these trackers' studies (comma-separated; default all)")
    p.add_argument("--table", action="store_true", help="only print the table of OUT")
    args = p.parse_args()
    rows = [json.loads(line) for line in Path(args.rows).read_text().splitlines()]
    out = Path(args.out)
    tops = {(d["sequence"], d["tracker"]): d["top"] for d in map(json.loads, out.read_text().splitlines())} \
        if out.is_file() else {}
    wanted = set(filter(None, args.trackers.split(",")))
    for row in rows if not args.table else ():
        key = (row["sequence"], row["tracker"])
        if row["route"] != args.route or key in tops or (wanted and row["tracker"] not in wanted):
            continue
        tops[key] = contenders(Path(args.data), row, Path(args.rows).with_suffix(""))
        with out.open("a") as f:
            f.write(json.dumps({"sequence": key[0], "tracker": key[1], "top": tops[key]}) + "\n")
        print(key, [(round(c["fresh"], 3), round(c["real"], 3)) for c in tops[key]], flush=True)
    print(f"{CONTENDERS} contenders a study, fresh seeds {FRESH.start}-{FRESH.stop - 1}:\n")
    print(table(rows, tops, args.route))


if __name__ == "__main__":
    main()
