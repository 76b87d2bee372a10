"""`mtt-sim learn-reid`: learn lmb's XQDA re-identification metric from crops of rendered episodes."""

from __future__ import annotations

from pathlib import Path

from mtt_sim.cli.arguments import (FORCE_HELP, SCENARIO_HELP, UsageError, add_dry_run, dry_run, estimate, integer,
                                   output_file, parse_seeds, print_fields, scenario_key)
from mtt_sim.real.layout import is_sequence


def add(subparsers) -> None:
    p = subparsers.add_parser("learn-reid", help="learn lmb's XQDA re-identification metric from rendered crops")
    p.add_argument("--scenario", type=scenario_key, default="mot17_like", help=SCENARIO_HELP)
    p.add_argument("--seeds", type=parse_seeds, default=parse_seeds("1000-1003"),
                   help="training episodes: a count, list or range (default 1000-1003, away from the experiments' 0..9)")
    p.add_argument("--frames", type=integer(1), default=300, help="frames per episode (default 300)")
    p.add_argument("--every", type=integer(1), default=15, help="take crops every this many frames (default 15)")
    p.add_argument("--dims", type=integer(1, 200), default=16, help="XQDA subspace dimension (default 16)")
    p.add_argument("--out", default="xqda.npz", help="where to write the metric (default: xqda.npz here)")
    p.add_argument("--install", action="store_true", help="replace the metric the package ships (every lmb uses it)")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from mtt_sim.trackers.parts import reid

    if is_sequence(args.scenario):
        raise UsageError("--scenario", f"{args.scenario!r} is a sequence folder: crops are rendered from a simulated "
                                       "scenario, a key or a .toml file")
    out = reid.METRIC_FILE if args.install else Path(args.out)
    output_file(str(out), args.force or args.install, "--out", (".npz",))
    if dry_run(args, estimate("learn-reid", [(len(args.seeds), "seeds")], [args.scenario], steps=args.frames,
                              unit="episodes")):
        return 0
    from mtt_sim.lab import learn_reid

    print_fields(learn_reid.learn(out, args.scenario, args.seeds, args.frames, args.every, args.dims, progress=True))
    if not args.install:
        print(f"use it with --tracker 'lmb:reid_metric={out}' (or relearn with --install to replace the shipped one)")
    return 0
