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
    python docs/experiments/tune_sim_to_real.py ../shared/data/mot15 OUT.jsonl --confirm 4 --workers 2

With --confirm N, each simulated route's row gets its tuned spec's and its defaults' scores on N fresh seeds of its
source (`mtt_sim.lab.confirm`); the table's picks then rank by those, and it adds what the routes would recover
keeping the defaults wherever the fresh seeds do not confirm the study's gain.
"""

from __future__ import annotations

import argparse
import json
import statistics
import tomllib
from pathlib import Path

from mtt_sim.env import TrackingEnv
from mtt_sim.lab.confirm import confirm, fresh_seeds
from mtt_sim.lab.experiment import run_episode
from mtt_sim.lab.routes import camera_kind, records
from mtt_sim.lab.tune import tune
from mtt_sim.metrics.goals import goals
from mtt_sim.sim2real.calibrate import calibrate, to_toml
from mtt_sim.sim2real.fit_scene import fit_scene

ROUTES = ("oracle", "twin", "scene", "generic", "generic_clock")
GENERIC = "mot17_like"
REAL_SCORING = {"env.max_tracks": 4096}
FRESH = 100  # confirmation seeds start here


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
    p.add_argument("--confirm", type=int, default=0, metavar="N",
                   help="only score the simulated routes' rows in OUT on N fresh seeds (those not scored so yet)")
    p.add_argument("--workers", type=int, default=1, help="processes for --confirm's episodes")
    args = p.parse_args()
    out = Path(args.out)
    if args.confirm:
        confirm_rows(args, out)
    rows = [json.loads(line) for line in _lines(out)] if args.table or args.record else None
    if args.record:
        print(record(rows, out.with_suffix("")))
        return
    if not args.table and not args.confirm:
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
                elif route in ("twin", "scene"):
                    source, config = source_of(route, folder, work)
                    result = tune(spec, [source], args.metric, args.trials, seeds, config)[0]
                else:
                    result = generic[spec, rate]
                defaults = defaults if defaults is not None else real_score(folder, spec, args.metric)
                row = {"sequence": folder.name, "tracker": spec, "route": route, "defaults": defaults,
                       "tuned_value": result.value, "real": real_score(folder, result.spec, args.metric),
                       "spec": result.spec, "trials": args.trials, "seeds": len(seeds)}
                with out.open("a") as f:
                    f.write(json.dumps(row) + "\n")
                print(json.dumps(row), flush=True)


def confirm_rows(args, out: Path) -> None:
    """Each simulated route's row in `out` without them gets "confirmed" and "confirmed_defaults": its tuned spec's
    and its defaults' mean score on --confirm seeds from FRESH on of the source it was tuned on (no study here runs
    that many seeds); `out` rewritten each row."""
    rows = [json.loads(line) for line in _lines(out)]
    work = out.with_suffix("")
    for row in rows:
        if row["route"] == "oracle" or "confirmed" in row:
            continue
        folder = Path(args.data) / row["sequence"]
        source, config = source_of(row["route"], folder, work)
        seeds = fresh_seeds(range(FRESH), args.confirm)
        got = confirm([row["spec"]], row["tracker"], [source], goals(args.metric), seeds, config, args.workers)
        row["confirmed"], row["confirmed_defaults"] = got.value[0], got.default_value[0]
        print(f"{row['sequence']} {row['tracker']} {row['route']}: " + "; ".join(got.lines()), flush=True)
        out.with_suffix(".tmp").write_text("".join(json.dumps(r) + "\n" for r in rows))
        out.with_suffix(".tmp").replace(out)


def source_of(route: str, folder: Path, work: Path) -> tuple[str, dict | None]:
    """The source a route tunes on for the sequence `folder` and its config (what `measure` tunes on)."""
    if route == "twin":
        sensor = tomllib.loads((work / f"fitted_without_{folder.name}.toml").read_text())["sensor"]
        return str(folder), {"sensor.model": "synthetic", **{f"sensor.{k}": v for k, v in sensor.items()}}
    if route == "scene":
        return str(work / f"scene_{folder.name}.toml"), None
    rate = TrackingEnv(str(folder)).source.info.frame_rate if route == "generic_clock" else None
    return GENERIC, {"world.frame_rate": rate} if rate else None


def _seeds(args, length: int) -> range:
    """--seeds, or with --frames as many as make about that many frames (1 to --seeds)."""
    return range(max(1, min(args.seeds, round(args.frames / length))) if args.frames else args.seeds)


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines() if path.is_file() else []


def real_score(folder: Path, spec: str, metric: str) -> float:
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
    lines += kept_defaults(by, routes)
    lines += picks(by, routes, metric)
    return "\n".join(lines)


def kept_defaults(by: dict, routes: list[str]) -> list[str]:
    """Per route with confirmed rows: the median share and the losses of over a point had the defaults been kept
    wherever the fresh seeds do not confirm the tuned spec's gain."""
    lines = []
    for r in routes[1:]:
        rows = [g for k, g in by.items() if k[2] == r and "confirmed" in g and (k[0], k[1], "oracle") in by]
        if not rows:
            continue
        shares, losses, kept = [], 0, 0
        for g in rows:
            held = g["confirmed"] > g["confirmed_defaults"]
            kept += not held
            gain = 100 * (g["real"] - g["defaults"]) if held else 0.0
            oracle = 100 * (by[g["tracker"], g["sequence"], "oracle"]["real"] - g["defaults"])
            losses += gain < -1
            if oracle >= 1:
                shares.append(gain / oracle)
        lines.append(f"- {r}, the defaults kept where fresh seeds do not confirm the gain ({kept} of {len(rows)}): "
                     f"median share {statistics.median(shares):.2f} over {len(shares)} pairs, {losses} losses of over "
                     "a point")
    return ["With the defaults kept where the fresh seeds disagree:", "", *lines, ""] if lines else []


def picks(by: dict, routes: list[str], metric: str) -> list[str]:
    """Per sequence, the tracker each route would pick (highest score on the route's own tuning source: on its fresh
    seeds where every tracker's row was confirmed) and its real score, beside the best real score of any tracker tuned
    on the sequence itself."""
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
            fresh = all("confirmed" in g for g in got)  # ranked on fresh seeds where all were confirmed
            pick = max(got, key=lambda g: g["confirmed"] if fresh else g["tuned_value"])
            gaps[r].append(100 * (best["real"] - pick["real"]))
            cells.append(f"{pick['tracker']} {100 * pick['real']:.1f}")
        lines.append(f"| {s} | {best['tracker']} {100 * best['real']:.1f} | " + " | ".join(cells) + " |")
    lines += ["", *(f"- {r}: its pick trails the best tuned tracker by a median {statistics.median(g):.1f} points, "
                    f"at most {max(g):.1f}; within 2 points on {sum(x <= 2 for x in g)} of {len(g)}"
                    for r, g in gaps.items() if g)]
    return lines


if __name__ == "__main__":
    main()
