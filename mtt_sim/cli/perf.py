"""`mtt-sim perf`: speed and memory of the env, the metrics and the trackers, each table printed as it is measured."""

from __future__ import annotations

import argparse

from mtt_sim.cli.arguments import add_dry_run, dry_run, estimate, integer


def add(subparsers) -> None:
    p = subparsers.add_parser("perf", help="speed and memory of the env, the metrics and the trackers, each against a "
                                           "same-run reference")
    p.add_argument("--repeats", type=integer(1), default=5, help="medians over this many repeats (default 5)")
    p.add_argument("--steps", type=integer(1), default=200, help="env steps per repeat (default 200)")
    p.add_argument("--sections", type=sections, default=None,
                   help=f"only these tables, comma-separated: {', '.join(SECTIONS)} (default all)")
    add_dry_run(p)
    p.set_defaults(func=run)


SECTIONS = ("env", "scenarios", "scaling", "motion", "metrics", "metrics memory", "jpda", "lmb", "rfs", "baselines",
            "particle filters", "sweeps")


def sections(text: str) -> list[str]:
    chosen = [s.strip() for s in text.split(",") if s.strip()]
    unknown = [s for s in chosen if s not in SECTIONS]
    if not chosen or unknown:
        raise argparse.ArgumentTypeError(f"{text!r}: sections are {', '.join(SECTIONS)}")
    return chosen


def run(args) -> int:
    if dry_run(args, estimate("perf", [(len(args.sections or SECTIONS), "tables"), (args.repeats, "repeats")],
                              unit="measurements")):
        return 0
    from tqdm import tqdm

    from mtt_sim.lab import perf, perf_motion

    sections = [("env", lambda: perf.report(perf.measure(repeats=args.repeats, steps=args.steps))),
                ("scenarios", lambda: perf.report_scenarios(perf.measure_scenarios(repeats=args.repeats, steps=args.steps))),
                ("scaling", lambda: perf.report_scaling(perf.measure_scaling(repeats=args.repeats))),
                ("motion", lambda: perf_motion.report_motion(perf_motion.measure_motion(args.repeats, args.steps))),
                ("metrics", lambda: perf.report_metrics(perf.measure_metrics(repeats=args.repeats))),
                ("metrics memory", lambda: perf.report_metrics_memory(perf.measure_metrics_memory(repeats=args.repeats))),
                ("jpda", lambda: perf.report_jpda(perf.measure_jpda(repeats=args.repeats))),
                ("lmb", lambda: perf.report_lmb(perf.measure_lmb(repeats=args.repeats))),
                ("rfs", lambda: perf.report_rfs(perf.measure_rfs(repeats=args.repeats))),
                ("baselines", lambda: perf.report_baselines(perf.measure_baselines(repeats=args.repeats))),
                ("particle filters", lambda: perf.report_pf(perf.measure_pf(repeats=args.repeats))),
                ("sweeps", lambda: perf.report_sweeps(perf.measure_sweeps(repeats=args.repeats)))]
    sections = [(name, measure) for name, measure in sections if args.sections is None or name in args.sections]
    with tqdm(sections, unit="section", leave=False) as bar:
        for name, measure in bar:
            bar.set_description(f"measuring {name}")
            bar.write(measure() + "\n")
    return 0
