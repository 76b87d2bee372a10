"""What bench and sweep share: the grid's arguments, and running a tracker x scenario x seed (x value) grid with its
tables, plot, records and failures."""

from __future__ import annotations

import argparse
import json
import shlex
import sys

from mtt_sim.cli import resuming
from mtt_sim.cli.arguments import (FORCE_HELP, INTERRUPTED, UsageError, add_dry_run, add_overrides, announce, dry_run,
                                   estimate, integer, metric_names, output_file, output_folder, parse_seeds, replaced,
                                   require, tracker_specs)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The arguments after the command's own: the trackers, seeds, workers, metrics and outputs."""
    parser.add_argument("--plot", help="write a plot, one panel per --metric (bench: bars per scenario; sweep: "
                                       "curves), as a PNG, PDF or SVG (needs the [plot] extra: matplotlib)")
    parser.add_argument("--trackers", type=tracker_specs, required=True,
                        help="tracker specs separated by commas, or by ';' when a spec has several parameters: "
                             "sort,iou,gnn:coast=true or 'sort:min_hits=1,max_age=5;iou'")
    parser.add_argument("--seeds", type=parse_seeds, default=parse_seeds("5"),
                        help="a count (5: seeds 0..4, the default), a list (3,7,11) or a range (100-199)")
    parser.add_argument("--workers", type=integer(1), default=1,
                        help="parallel processes, or a local Ray instance's CPUs (default 1)")
    parser.add_argument("--backend", choices=("local", "ray"), default="local",
                        help="local processes, or Ray tasks (the [ray] extra)")
    parser.add_argument("--address", help="with --backend ray: a Ray cluster's address (default: start a local one)")
    parser.add_argument("--metric", type=metric_names, default=["MOTA"],
                        help="metric(s) of the tables, comma-separated, any case (default MOTA)")
    parser.add_argument("--out", help="write every episode's record as it finishes (.csv or .json)")
    parser.add_argument("--results-dir",
                        help="write every episode's tracks as a MOTChallenge results file in this folder")
    parser.add_argument("--force", action="store_true", help=FORCE_HELP)
    resuming.add(parser, "--out")
    add_overrides(parser, "overrides for every episode")
    add_dry_run(parser)


def check_plot(args) -> None:
    """--plot's checks, before any work: matplotlib at hand, a file that can be written."""
    if args.plot:
        require("matplotlib", "--plot", "plot")
        output_file(args.plot, args.force, "--plot", (".png", ".pdf", ".svg"))


def run(args, scenarios: list[str], overrides: dict, configs, table, plot) -> int:
    """Run a bench or sweep grid: records written as they finish, a table(records, metric) per metric, with --plot
    plot(records) (one panel per metric), and the failed episodes at the end, and on Ctrl-C or SIGTERM the workers
    stopped and what finished kept (and, with --out, its journal, which --resume takes up). Exit status: 0, 1 if an
    episode failed, 130 if interrupted."""
    out = output_file(args.out, resuming.force(args, args.out, "--out"), "--out", (".csv", ".json"))
    if args.results_dir:
        output_folder(args.results_dir, args.force or args.resume, "--results-dir", "write into it")
    if args.backend == "ray":
        require("ray", "--backend", "ray")
    elif args.address:
        raise UsageError("--address", f"{args.address!r}: a Ray cluster's address goes with --backend ray")
    columns = (len(configs), "values") if configs else (len(scenarios), "scenarios")
    work = estimate(args.command, [(len(args.trackers), "trackers"), columns, (len(args.seeds), "seeds")], scenarios,
                    overrides, configs or ({},))
    if dry_run(args, work):
        return 0
    from mtt_sim.lab import experiment

    finished = []
    definition = {"command": args.command, "trackers": args.trackers, "scenarios": scenarios, "seeds": list(args.seeds),
                  "config": overrides, "configs": configs, "results_dir": args.results_dir}
    journal = resuming.journal(out, definition, args.resume, "episodes") if out else None
    announce(work)
    record_file = experiment.RecordFile(out) if out else None

    def keep(record):
        finished.append(record)
        if record_file:
            record_file.append(record)

    interrupted = False
    try:
        records = experiment.run_grid(args.trackers, scenarios, args.seeds, config=overrides, configs=configs,
                                      workers=args.workers, progress=True, backend=args.backend, address=args.address,
                                      on_record=keep, results_dir=args.results_dir, journal=journal)
    except KeyboardInterrupt:
        records, interrupted = finished, True
    finally:
        for file in filter(None, (record_file, journal)):
            file.close()
    if out and not interrupted:
        experiment.write_records(records, out)  # again, in grid order
        journal.finish()
    done = [r for r in records if r is not None]
    print("\n\n".join(filter(None, (table(done, m) for m in args.metric))))
    scored = [r for r in done if r["metrics"] is not None]
    if args.plot and scored:
        plot(scored)
        print(f"\nplot: {args.plot} ({', '.join(args.metric)})" + replaced(args.force))
    failed = [r for r in done if r["error"]]
    if failed:
        print(f"\n{len(failed)} of {len(done)} episodes failed:")
        for r in failed:
            again = ["mtt-sim", "run", r["scenario"], "--tracker", r["tracker"], "--seed", str(r["seed"])]
            config = [f"{k}={json.dumps(v)}" for k, v in r["config"].items()]
            print(f"  {r['tracker']} on {r['scenario']} seed {r['seed']}: {r['error']}\n"
                  f"    again: {shlex.join(again + (['--config', *config] if config else []))}")
    if out:
        print(f"\nrecords: {out}" + replaced(args.force))
    if args.results_dir:
        print(f"results files: {args.results_dir}/<tracker>/<scenario>[-seed<k>].txt")
    if interrupted:
        size = len(args.trackers) * len(scenarios) * len(args.seeds) * len(configs or [{}])
        print(f"mtt-sim {args.command}: interrupted; {len(done)} of {size} episodes finished"
              + (f", their records in {out}; the same command with --resume runs the rest" if out else ""),
              file=sys.stderr)
        return INTERRUPTED
    return 1 if failed else 0
