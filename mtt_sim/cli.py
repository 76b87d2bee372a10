"""The `mtt-sim` command: list scenarios, run an episode, bench and sweep trackers, measure speed, print the config."""

from __future__ import annotations

import argparse
import json
import sys
import tomllib

from . import experiment, perf, scenario

SUMMARY_KEYS = ("MOTA", "MOTP", "IDF1", "HOTA", "DetA", "AssA", "LocA", "GOSPA", "CentreError", "TP", "FP", "FN", "IDSW", "Frag",
                "MT", "PT", "ML", "num_frames", "num_gt_dets", "num_gt_ids")


def parse_overrides(items: list[str]) -> dict:
    """`key=value` strings to a dotted-key dict; values are read as TOML (numbers, booleans, lists), else as text."""
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise scenario.ConfigError(f"--config {item!r}: expected key=value, e.g. sensor.clutter_rate=5")
        out[key] = _toml_value(value)
    return out


def _toml_value(text: str):
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def cmd_run(args) -> int:
    record = experiment.run_episode(args.scenario, args.tracker, args.seed, parse_overrides(args.config),
                                    video=args.video, steps=args.steps or None)
    summary = {"scenario": args.scenario, "tracker": args.tracker, "seed": args.seed,
               **{k: record["metrics"][k] for k in SUMMARY_KEYS},
               "tracker_fps": record["tracker_fps"], "env_fps": record["env_fps"]}
    if args.json:
        print(json.dumps(summary))
        return 0
    for k, v in summary.items():
        print(f"{k:12s} {v:.3f}" if isinstance(v, float) else f"{k:12s} {v}")
    if args.video:
        print(f"{'video':12s} {args.video}")
    return 0


def _grid_output(args, records, tables):
    if args.out:
        experiment.write_records(records, args.out)
    print("\n\n".join(tables))
    if args.out:
        print(f"\nrecords: {args.out}")


def cmd_bench(args) -> int:
    records = experiment.run_grid(args.trackers.split(","), args.scenarios.split(","), args.seeds,
                                  config=parse_overrides(args.config), workers=args.workers, progress=True,
                                  backend=args.backend, address=args.address)
    title = args.scenarios if args.by == "target" else ""
    _grid_output(args, records, [experiment.markdown(experiment.summarize(records, m, by=args.by), title)
                                 for m in args.metric.split(",")])
    return 0


def cmd_sweep(args) -> int:
    key, sep, values = args.param.partition("=")
    if not sep or not values:
        raise scenario.ConfigError(f"--param {args.param!r}: expected key=v1,v2,..., e.g. sensor.clutter_rate=0,5,10")
    values = [_toml_value(v) for v in values.split(",")]
    records = experiment.run_grid(args.trackers.split(","), [args.scenario], args.seeds,
                                  config=parse_overrides(args.config), configs=[{key: v} for v in values],
                                  workers=args.workers, progress=True, backend=args.backend, address=args.address)
    tables = []
    for metric in args.metric.split(","):
        rows = experiment.summarize(records, metric, by="config")
        for r in rows:
            r["column"] = f"{key.split('.')[-1]}={json.loads(r['column'])[key]}"
        tables.append(experiment.markdown(rows, f"{args.scenario}, sweeping {key}"))
    _grid_output(args, records, tables)
    if args.plot:
        experiment.sweep_plot(rows, key, values, args.plot)
        print(f"plot: {args.plot} ({metric})")
    return 0


def cmd_list(args) -> int:
    from . import env_ids
    ids = env_ids()
    for key, desc in scenario.available().items():
        print(f"{key:14s} {ids[key]:26s} {desc}")
    return 0


def cmd_perf(args) -> int:
    print(perf.report(perf.measure(repeats=args.repeats, steps=args.steps)))
    print()
    print(perf.report_metrics(perf.measure_metrics(repeats=args.repeats)))
    print()
    print(perf.report_metrics_memory(perf.measure_metrics_memory(repeats=args.repeats)))
    print()
    print(perf.report_jpda(perf.measure_jpda(repeats=args.repeats)))
    print()
    print(perf.report_lmb(perf.measure_lmb(repeats=args.repeats)))
    print()
    print(perf.report_pf(perf.measure_pf(repeats=args.repeats)))
    return 0


def cmd_learn_reid(args) -> int:
    from . import learn_reid
    summary = learn_reid.learn(args.scenario, range(args.first_seed, args.first_seed + args.seeds), args.frames,
                               args.every, args.dims, args.out)
    for k, v in summary.items():
        print(f"{k:12s} {v}")
    return 0


def cmd_export(args) -> int:
    from . import motchallenge
    summary = motchallenge.export(args.scenario, args.out, args.seed, args.steps or None, parse_overrides(args.config))
    for k, v in summary.items():
        print(f"{k:12s} {v}")
    return 0


def cmd_eval(args) -> int:
    from . import motchallenge
    s = scenario.ScoringConfig()
    metrics = motchallenge.evaluate_results(args.gt, args.results, similarity=args.similarity, threshold=args.threshold,
                                            zero_distance=s.zero_distance, gospa_c=s.gospa_c, gospa_p=s.gospa_p)
    summary = {k: metrics[k] for k in SUMMARY_KEYS}
    if args.json:
        print(json.dumps(summary))
        return 0
    for k, v in summary.items():
        print(f"{k:12s} {v:.3f}" if isinstance(v, float) else f"{k:12s} {v}")
    return 0


def cmd_config(args) -> int:
    if args.scenario:
        print(json.dumps(scenario.to_mapping(scenario.load(args.scenario, parse_overrides(args.config))), indent=2))
    else:
        print(scenario.reference_table())
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="mtt-sim", description="A Gymnasium environment for video multi-target tracking.")
    sub = p.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="scenarios with their env ids and one-line descriptions").set_defaults(func=cmd_list)
    run = sub.add_parser("run", help="run one episode with a tracker and print its metrics")
    run.add_argument("scenario", help="scenario key (see `mtt-sim list`) or a .toml file")
    run.add_argument("--tracker", default="sort", help="tracker spec, e.g. sort or 'sort:max_age=3' (default: sort)")
    run.add_argument("--seed", type=int, default=0)
    run.add_argument("--steps", type=int, default=0, help="at most this many steps (default: the scenario's env.max_steps)")
    run.add_argument("--video", help="write an annotated video (.mp4 or .avi)")
    run.add_argument("--config", nargs="*", default=[], metavar="KEY=VALUE", help="overrides, e.g. sensor.clutter_rate=5")
    run.add_argument("--json", action="store_true", help="print the summary as JSON")
    run.set_defaults(func=cmd_run)
    for name, func, text in (("bench", cmd_bench, "a tracker x scenario x seed grid, as a table of mean and 95% interval"),
                             ("sweep", cmd_sweep, "a stress curve: one scenario, one parameter over several values")):
        g = sub.add_parser(name, help=text)
        if name == "bench":
            g.add_argument("--scenarios", required=True, help="comma-separated scenario keys")
            g.add_argument("--by", choices=("scenario", "target"), default="scenario",
                           help="columns: scenarios, or ground-truth ids for the per-target metrics CentreError and "
                                "Coverage (hand-initialised trackers; one scenario)")
        else:
            g.add_argument("scenario")
            g.add_argument("--param", required=True, metavar="KEY=V1,V2,...", help="e.g. sensor.clutter_rate=0,2,5,10,20")
            g.add_argument("--plot", help="write the curve as a PNG (needs the [plot] extra: matplotlib)")
        g.add_argument("--trackers", required=True, help="comma-separated tracker specs, e.g. sort,iou,'gnn:coast=true'")
        g.add_argument("--seeds", type=int, default=5, help="seeds 0..N-1 (default 5)")
        g.add_argument("--workers", type=int, default=1, help="parallel processes, or a local Ray instance's CPUs "
                                                               "(default 1)")
        g.add_argument("--backend", choices=experiment.BACKENDS, default="local",
                       help="local processes, or Ray tasks (the [ray] extra)")
        g.add_argument("--address", help="with --backend ray: a Ray cluster's address (default: start a local one)")
        g.add_argument("--metric", default="MOTA", help="metric(s) of the tables, comma-separated (default MOTA)")
        g.add_argument("--out", help="write every episode's record (.csv, or .json)")
        g.add_argument("--config", nargs="*", default=[], metavar="KEY=VALUE", help="overrides for every episode")
        g.set_defaults(func=func)
    pf = sub.add_parser("perf", help="env steps/s and metrics cost at 20 and 200 targets, each against a same-run reference")
    pf.add_argument("--repeats", type=int, default=5)
    pf.add_argument("--steps", type=int, default=200)
    pf.set_defaults(func=cmd_perf)
    lr = sub.add_parser("learn-reid", help="learn lmb's XQDA re-identification metric from rendered crops")
    lr.add_argument("--scenario", default="mot17_like")
    lr.add_argument("--first-seed", type=int, default=1000, help="training seeds start here (default 1000, away "
                                                                   "from the experiments' 0..9)")
    lr.add_argument("--seeds", type=int, default=4)
    lr.add_argument("--frames", type=int, default=300)
    lr.add_argument("--every", type=int, default=15, help="take crops every this many frames")
    lr.add_argument("--dims", type=int, default=16, help="XQDA subspace dimension")
    lr.add_argument("--out", default=None, help="where to write (default: the file the package ships)")
    lr.set_defaults(func=cmd_learn_reid)
    ex = sub.add_parser("export", help="write an episode as a MOTChallenge sequence (frames, gt, detections)")
    ex.add_argument("scenario")
    ex.add_argument("--out", required=True, help="the sequence folder to write")
    ex.add_argument("--seed", type=int, default=0)
    ex.add_argument("--steps", type=int, default=0, help="at most this many frames (default: env.max_steps)")
    ex.add_argument("--config", nargs="*", default=[], metavar="KEY=VALUE")
    ex.set_defaults(func=cmd_export)
    ev = sub.add_parser("eval", help="score a MOTChallenge results file against an exported sequence")
    ev.add_argument("--gt", required=True, help="the sequence folder (with seqinfo.ini and gt/gt.txt)")
    ev.add_argument("--results", required=True, help="frame, id, x, y, w, h, ... per line")
    ev.add_argument("--similarity", choices=("iou", "centroid"), default="iou")
    ev.add_argument("--threshold", type=float, default=0.5)
    ev.add_argument("--json", action="store_true")
    ev.set_defaults(func=cmd_eval)
    cf = sub.add_parser("config", help="the configuration reference, or one scenario's resolved configuration")
    cf.add_argument("scenario", nargs="?")
    cf.add_argument("--config", nargs="*", default=[], metavar="KEY=VALUE")
    cf.set_defaults(func=cmd_config)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, OSError, ImportError) as err:  # bad configs, specs, values, files, a missing extra
        print(f"mtt-sim: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
