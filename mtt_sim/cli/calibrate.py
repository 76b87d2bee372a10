"""`mtt-sim calibrate`: fit the synthetic detector to real detections, print the fit beside the data and write it as
a [sensor] table."""

from __future__ import annotations

import shlex

from mtt_sim.cli.arguments import (FORCE_HELP, add_dry_run, announce, calibration_folder, distinct_folders, dry_run,
                                   estimate, integer, output_file, replaced)


def add(subparsers) -> None:
    p = subparsers.add_parser("calibrate", help="fit the synthetic detector to real detections: print the fit beside "
                                                "the data and write a [sensor] table")
    p.add_argument("folders", nargs="+", type=calibration_folder, metavar="DIR",
                   help="sequence folders with gt/gt.txt and det/det.txt (fitted together)")
    p.add_argument("--out", required=True, help="the [sensor] table to write (.toml)")
    p.add_argument("--seeds", type=integer(1), default=3, help="twin runs averaged in the check (default 3)")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    distinct_folders(args.folders)
    out = output_file(args.out, args.force, "--out", (".toml",))
    work = estimate("calibrate", [(len(args.folders), "sequences"), (args.seeds, "seeds")], args.folders,
                    unit="twin runs")
    if dry_run(args, work):
        return 0
    announce(work)
    from mtt_sim.sim2real import calibrate

    fitted = calibrate.calibrate(args.folders, seeds=args.seeds, progress=True)
    print(calibrate.report(fitted))
    out.write_text(calibrate.to_toml(fitted))
    print(f"\nsensor: {out}" + replaced(args.force)
          + f"; replay a sequence through it: mtt-sim run DIR --detector synthetic --sensor {shlex.quote(str(out))}")
    return 0
