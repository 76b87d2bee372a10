"""Sim-to-real tuning, measured: for each MOTChallenge sequence and tracker, tune on (a) the sequence itself (the
oracle), (b) its twin (its ground-truth people through a detector fitted on the other sequences), (c) its label-free
scene (`mtt-sim fit-scene` on its detections, the same detector) and (d) the generic `mot17_like`, at its own 25
frames a second, or with `--routes generic_clock` at the sequence's (its seqinfo.ini, no label); score every
result and the defaults on the real sequence. Rows go to OUT.jsonl as they come (a rerun skips the rows there, so
several processes can share one file, each with its own --trackers); then a Markdown table of the real gains, the
share of the oracle's gain each route recovers, and which tracker each route would pick.

    python docs/experiments/tune_sim_to_real.py ../shared/data/mot15 OUT.jsonl --trackers sort,bytetrack --trials 30
    python docs/experiments/tune_sim_to_real.py ../shared/data/mot15 OUT.jsonl --trackers jpda --trials 20 \
        --seeds 4 --frames 400
    python docs/experiments/tune_sim_to_real.py ../shared/data/mot15 OUT.jsonl --record   # RECORD for lab/routes.py
"""

from __future__ import annotations

import argparse
import json
import statistics
import tomllib
from pathlib import Path

from mtt_sim.env import TrackingEnv
from mtt_sim.lab.experiment import run_episode
from mtt_sim.lab.routes import camera_kind, records
from mtt_sim.lab.tune import tune
from mtt_sim.sim2real.calibrate import calibrate, to_toml
from mtt_sim.sim2real.fit_scene import fit_scene

ROUTES = ("oracle", "twin", "scene", "generic", "generic_clock")
GENERIC = "mot17_like"
REAL_SCORING = {"env.max_tracks": 4096}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data", help="a folder of MOTChallenge sequence folders")
    p.add_argument("out", help="the rows, one JSON object a line")
    p.add_argument("--trackers", default="sort,bytetrack")
    p.add_argument("--routes", default=",".join(ROUTES[:4]), help=f"of {', '.join(ROUTES)}")
    p.add_argument("--sequences", default="", help="only these sequences (comma-separated names; default all)")
    p.add_argument("--metric", default="HOTA")
    p.add_argument("--trials", type=int, default=30)
    p.add_argument("--seeds", type=int, default=2, help="at most this many episodes per trial on a simulated source")
    p.add_argument("--frames", type=int, default=0,
                   help="fewer seeds for long sequences: about this many frames a trial (0: always --seeds)")
    p.add_argument("--table", action="store_true", help="only print the table of the rows in OUT")
    p.add_argument("--record", action="store_true",
                   help="only print the routes' record of the rows in OUT, for mtt_sim/lab/routes.py's RECORD")
    args = p.parse_args()
    out = Path(args.out)
    rows = [json.loads(line) for line in _lines(out)] if args.table or args.record else None
    if args.record:
        print(record(rows, out.with_suffix("")))
        return
    if not args.table:
        measure(args, out)
    print(table(rows or [json.loads(line) for line in out.read_text().splitlines()], args.metric))


def measure(args, out: Path) -> None:
    folders = sorted(f for f in Path(args.data).iterdir() if (f / "gt" / "gt.txt").is_file())
    chosen = set(args.sequences.split(",")) if args.sequences else {f.name for f in folders}
    work = out.with_suffix("")
    work.mkdir(parents=True, exist_ok=True)
    done = {(r["sequence"], r["tracker"], r["route"]) for r in map(json.loads, _lines(out))}
    generic = {}
    for folder in (f for f in folders if f.name in chosen):
        sensor = work / f"fitted_without_{folder.name}.toml"
        if not sensor.is_file():
            sensor.write_text(to_toml(calibrate([f for f in folders if f != folder], seeds=1)))
        scene = work / f"scene_{folder.name}.toml"
        if not scene.is_file():
            scene.write_text(fit_scene(folder, sensor, seeds=())[3])
        twin = {"sensor.model": "synthetic",
                **{f"sensor.{k}": v for k, v in tomllib.loads(sensor.read_text())["sensor"].items()}}
        recording = TrackingEnv(str(folder)).source
        seeds = _seeds(args, recording.length)
        for spec in args.trackers.split(","):
            defaults = None
            for route in args.routes.split(","):
                if (folder.name, spec, route) in done:
                    continue
                rate = recording.info.frame_rate if route == "generic_clock" else None  # None: the scene's own
                if route.startswith("generic") and (spec, rate) not in generic:
                    generic[spec, rate] = tune(spec, [GENERIC], args.metric, args.trials,
                                               _seeds(args, TrackingEnv(GENERIC).source.config.env.max_steps),
                                               {"world.frame_rate": rate} if rate else None)[0]
                if route == "oracle":
                    result = tune(spec, [str(folder)], args.metric, args.trials)[0]
                elif route == "twin":
                    result = tune(spec, [str(folder)], args.metric, args.trials, seeds, twin)[0]
                elif route == "scene":
                    result = tune(spec, [str(scene)], args.metric, args.trials, seeds)[0]
                else:
                    result = generic[spec, rate]
                defaults = defaults if defaults is not None else _real(folder, spec, args.metric)
                row = {"sequence": folder.name, "tracker": spec, "route": route, "defaults": defaults,
                       "tuned_value": result.value, "real": _real(folder, result.spec, args.metric),
                       "spec": result.spec, "trials": args.trials, "seeds": len(seeds)}
                with out.open("a") as f:
                    f.write(json.dumps(row) + "\n")
                print(json.dumps(row), flush=True)


def _seeds(args, length: int) -> range:
    """--seeds, or with --frames as many as make about that many frames (1 to --seeds)."""
    return range(max(1, min(args.seeds, round(args.frames / length))) if args.frames else args.seeds)


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines() if path.is_file() else []


def _real(folder: Path, spec: str, metric: str) -> float:
    """The spec's score on the real sequence. The action space is widened: a spec tuned in simulation may report more
    tracks on real video than the env's default 256 rows, and that is a poor score, not a reason to stop the run."""
    return run_episode(str(folder), spec, config=REAL_SCORING)["metrics"][metric]


def record(rows: list[dict], work: Path) -> str:
    """The routes' record of `rows` as RECORD's Python text: the scene's per the camera kind its fit found (the scene
    files in `work`)."""
    kinds = {r["sequence"]: camera_kind((work / f"scene_{r['sequence']}.toml").read_text()) for r in rows}
    return "RECORD = {\n" + "".join(f'    ("{route}", "{kind}", "{tracker}"): {value!r},\n'
                                     for (route, kind, tracker), value in records(rows, kinds).items()) + "}"


def table(rows: list[dict], metric: str) -> str:
    """Per tracker and sequence: the defaults' real score and each route's real gain (points), the share of the
    oracle's gain each simulated route recovers where the oracle gains at least a point, the medians, the losses of
    over a point, and the tracker each route picks per sequence (its best score on its own tuning source)."""
    by = {(r["tracker"], r["sequence"], r["route"]): r for r in rows}
    routes = [r for r in ROUTES if any(k[2] == r for k in by)]
    pairs = sorted({(t, s) for t, s, _ in by}, key=lambda k: (k[1], k[0]))
    lines = [f"| tracker | sequence | {metric} defaults | " + " | ".join(f"{r} gain" for r in routes) + " | "
             + " | ".join(f"{r} / oracle" for r in routes[1:]) + " |", "|---|---|" + "---:|" * (2 * len(routes))]
    shares, losses = {}, []
    for t, s in pairs:
        got = {r: by.get((t, s, r)) for r in routes}
        defaults = next(g["defaults"] for g in got.values() if g)
        gain = {r: 100 * (g["real"] - defaults) if g else None for r, g in got.items()}
        oracle = gain.get("oracle")
        cells = []
        for r in routes[1:]:
            share = gain[r] / oracle if gain[r] is not None and oracle is not None and oracle >= 1 else None
            if share is not None:
                shares.setdefault((r, t), []).append(share)
            if gain[r] is not None and gain[r] < -1:
                losses.append(f"{t} on {s} tuned on its {r}: {gain[r]:+.1f}")
            cells.append(f"{share:.2f}" if share is not None else "-")
        lines.append(f"| {t} | {s} | {100 * defaults:.1f} | "
                     + " | ".join(f"{gain[r]:+.1f}" if gain[r] is not None else "" for r in routes) + " | "
                     + " | ".join(cells) + " |")
    lines += ["", "Median share of the oracle's gain recovered (pairs where the oracle gains at least a point):", ""]
    for r in routes[1:]:
        everyone = [x for (route, _), v in shares.items() if route == r for x in v]
        if everyone:
            per = ", ".join(f"{t} {statistics.median(v):.2f}" for (route, t), v in shares.items() if route == r)
            lines.append(f"- {r}: {statistics.median(everyone):.2f} over {len(everyone)} pairs ({per})")
    lines += ["", "Losses of over a point against the defaults: " + ("; ".join(losses) or "none"), ""]
    lines += picks(by, routes, metric)
    return "\n".join(lines)


def picks(by: dict, routes: list[str], metric: str) -> list[str]:
    """Per sequence, the tracker each route would pick (highest score on the route's own tuning source) and its real
    score, beside the best real score of any tracker tuned on the sequence itself."""
    lines = [f"| sequence | best tuned ({metric}) | " + " | ".join(f"{r} picks" for r in routes) + " |",
             "|---|---|" + "---|" * len(routes)]
    gaps = {r: [] for r in routes}
    for s in sorted({k[1] for k in by}):
        oracle = [by[k] for k in by if k[1] == s and k[2] == "oracle"]
        if not oracle:
            continue
        best = max(oracle, key=lambda g: g["real"])
        cells = []
        for r in routes:
            got = [by[k] for k in by if k[1] == s and k[2] == r]
            if len(got) < len(oracle):  # a pick among some of the trackers is none (rows still coming, say)
                cells.append("-")
                continue
            pick = max(got, key=lambda g: g["tuned_value"])
            gaps[r].append(100 * (best["real"] - pick["real"]))
            cells.append(f"{pick['tracker']} {100 * pick['real']:.1f}")
        lines.append(f"| {s} | {best['tracker']} {100 * best['real']:.1f} | " + " | ".join(cells) + " |")
    lines += ["", *(f"- {r}: its pick trails the best tuned tracker by a median {statistics.median(g):.1f} points, "
                    f"at most {max(g):.1f}" for r, g in gaps.items() if g)]
    return lines


if __name__ == "__main__":
    main()
