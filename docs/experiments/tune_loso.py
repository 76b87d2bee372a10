"""A fair, tuned comparison on real data: every tracker tuned leave-one-sequence-out (picked on all sequences but
one, scored on that one) beside its defaults, as mean MOTA, IDF1 and HOTA over the held-out sequences.

The search is random, from one pool per tracker: the defaults and `--candidates` parameter sets drawn from the
tracker's declared search space (Optuna's RandomSampler, seeded), each run once on every sequence. A fold picks the
candidate with the best mean `--metric` on its training sequences alone, so the held-out sequence never steers the
pick; one shared pool makes the eight folds cost one search instead of eight. Per-candidate scores go to OUT.jsonl as
they come (a rerun skips the trackers there); then a Markdown table.

    python docs/experiments/tune_loso.py ../shared/data/mot15 OUT.jsonl --trackers sort,lmb:reid=false --candidates 48
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
from pathlib import Path

import optuna
from mtt_sim.trackers.base import parse_spec, search_space, spec_of

from mtt_sim import trackers
from mtt_sim.lab.experiment import run_episode

METRICS = ("MOTA", "IDF1", "HOTA")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data", help="a folder of MOTChallenge sequence folders")
    p.add_argument("out", help="per-candidate scores, one JSON object a line")
    p.add_argument("--trackers", default="sort,iou,bytetrack,gmphd,gnn,lmb:reid=false,jpda,jpda_exact")
    p.add_argument("--candidates", type=int, default=48)
    p.add_argument("--metric", default="HOTA", choices=METRICS)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--table", action="store_true", help="only print the table of the scores in OUT")
    args = p.parse_args()
    out = Path(args.out)
    if not args.table:
        folders = sorted(f for f in Path(args.data).iterdir() if (f / "gt" / "gt.txt").is_file())
        done = {json.loads(line)["tracker"] for line in _lines(out)}
        for spec in args.trackers.split(","):
            if spec not in done:
                search(spec, folders, args.candidates, args.seed, out)
    print(table([json.loads(line) for line in _lines(out)], args.metric))


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines() if path.is_file() else []


def candidates(spec: str, count: int, seed: int) -> list[str]:
    """`spec` itself, then `count` specs drawn at random from its tracker's search space (fixed keys kept)."""
    name, fixed = parse_spec(spec)
    space = search_space(trackers.make(spec).name, fixed)
    study = optuna.create_study(sampler=optuna.samplers.RandomSampler(seed=seed))
    drawn = [spec]
    for _ in range(count):
        trial = study.ask()
        drawn.append(spec_of(name, {**fixed, **{k: p.suggest(trial, k) for k, p in space.items()}}))
        study.tell(trial, 0.0)
    return drawn


def search(spec: str, folders: list[Path], count: int, seed: int, out: Path) -> None:
    """Run every candidate on every sequence; a failed episode scores the candidate NaN there (never picked)."""
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    for index, candidate in enumerate(candidates(spec, count, seed)):
        scores = {}
        for folder in folders:
            try:
                metrics = run_episode(str(folder), candidate)["metrics"]
                scores[folder.name] = {m: metrics[m] for m in METRICS}
            except Exception as err:  # noqa: BLE001  (a drawn setting may break a tracker; it is not picked)
                scores[folder.name] = {m: math.nan for m in METRICS} | {"error": str(err)[:200]}
        row = {"tracker": spec, "candidate": index, "spec": candidate, "scores": scores}
        with out.open("a") as f:
            f.write(json.dumps(row) + "\n")
        print(spec, index, flush=True)


def table(rows: list[dict], metric: str) -> str:
    """Per tracker: the defaults' mean scores and the leave-one-out tuned ones (each sequence scored by the candidate
    picked on the others), on how many held-out sequences the pick scores `metric` at least as the defaults do (what
    tuning on other cameras' labels gives a camera, the ceiling of a route that sees nothing of it), and how often
    the pick changed from the defaults."""
    lines = ["| tracker | candidates | " + " | ".join(f"{m} defaults | {m} tuned" for m in METRICS)
             + f" | held out, {metric} >= defaults |", "|---|---:|" + "---:|" * (2 * len(METRICS) + 1)]
    picks_text = []
    for spec in dict.fromkeys(r["tracker"] for r in rows):
        pool = [r for r in rows if r["tracker"] == spec]
        sequences = sorted(pool[0]["scores"])
        held_out, picked = {m: [] for m in METRICS}, []
        for s in sequences:
            train = [t for t in sequences if t != s]
            best = max(pool, key=lambda r: _mean(r, train, metric))
            picked.append(f"{s}: {best['spec']}")
            for m in METRICS:
                held_out[m].append(best["scores"][s][m])
        defaults = pool[0]
        cells = [f"{100 * _mean(defaults, sequences, m):.1f} | {100 * statistics.fmean(held_out[m]):.1f}"
                 for m in METRICS]
        held = sum(best >= defaults["scores"][s][metric] for best, s in zip(held_out[metric], sequences))
        lines.append(f"| {spec} | {len(pool) - 1} | " + " | ".join(cells) + f" | {held} of {len(sequences)} |")
        distinct = {}
        for p in picked:
            sequence, chosen = p.split(": ", 1)
            distinct.setdefault(chosen, []).append(sequence)
        picks_text += [f"- {spec}: {len(distinct)} distinct picks over {len(sequences)} folds",
                       *(f"  - held out {', '.join(s)}: `{c}`" for c, s in distinct.items())]
    return "\n".join(lines + ["", f"Picked by mean {metric} on the other sequences:", *picks_text])


def _mean(row: dict, sequences: list[str], metric: str) -> float:
    """The mean of `metric` over `sequences`; -inf where any episode failed, so such a candidate is never picked."""
    values = [row["scores"][s][metric] for s in sequences]
    return -math.inf if any(math.isnan(v) for v in values) else statistics.fmean(values)


if __name__ == "__main__":
    main()
