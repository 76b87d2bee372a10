"""`mtt-sim validate`: the sim-to-real check, trackers on real detections against their synthetic twins."""

from __future__ import annotations

from mtt_sim.cli.arguments import (FORCE_HELP, add_dry_run, announce, calibration_folder, distinct_folders, dry_run,
                                   estimate, integer, output_file, replaced, tracker_specs)


def add(subparsers) -> None:
    p = subparsers.add_parser("validate", help="the sim-to-real check: trackers on real detections against the twins "
                                               "(fitted here, on the other sequences, memoryless)")
    p.add_argument("folders", nargs="+", type=calibration_folder, metavar="DIR",
                   help="sequence folders with gt/gt.txt and det/det.txt (two or more for leave-one-out)")
    p.add_argument("--trackers", type=tracker_specs, default=None,
                   help="tracker specs (default: sort,iou,bytetrack,gnn,gmphd,lmb:reid=false,jpda)")
    p.add_argument("--seeds", type=integer(1), default=3, help="twin episodes per sequence and tracker (default 3)")
    p.add_argument("--workers", type=integer(1), default=1, help="parallel processes (default 1)")
    p.add_argument("--scene", action="store_true",
                   help="also judge each sequence's label-free fitted scene (fit-scene on its detections alone, the "
                        "detector fitted on the others): what a camera without labels predicts of the trackers")
    p.add_argument("--out", help="also write the tables to this Markdown file (.md)")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    distinct_folders(args.folders)
    out = output_file(args.out, args.force, "--out", (".md",))
    from mtt_sim.sim2real import validate

    specs = args.trackers or validate.TRACKERS
    twins = [t for t in validate.TWINS + ((validate.SCENE,) if args.scene else ())
             if len(args.folders) > 1 or not t.leave_one_out]
    runs = (len(args.folders), "sequences"), (len(specs), "trackers"), (1 + len(twins) * args.seeds, "runs (1 real, "
                                                                         f"{len(twins)} twins x {args.seeds} seeds)")
    work = estimate("validate", runs, args.folders)
    if dry_run(args, work):
        return 0
    announce(work)
    result = validate.validate(args.folders, specs, seeds=args.seeds, workers=args.workers, progress=True,
                               scene=args.scene)
    text = validate.markdown(result)
    print(text)
    if out:
        out.write_text(text)
        print(f"tables: {out}" + replaced(args.force))
    return 1 if result.failed else 0
