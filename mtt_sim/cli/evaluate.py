"""`mtt-sim eval`: score a MOTChallenge results file against a sequence's ground truth, as TrackEval does."""

from __future__ import annotations

import json
from pathlib import Path

from mtt_sim.cli.arguments import UsageError, add_dry_run, dry_run, estimate, fraction, print_summary
from mtt_sim.sim import scenario


def add(subparsers) -> None:
    p = subparsers.add_parser("eval", help="score a MOTChallenge results file against a sequence's ground truth, as "
                                           "TrackEval")
    p.add_argument("--gt", required=True, help="the sequence folder (gt/gt.txt; seqinfo.ini if it has one)")
    p.add_argument("--benchmark", choices=("MOT15", "MOT16", "MOT17", "MOT20"),
                   help="the scoring rules (default: from the folder's name, else MOT17 where gt.txt has classes, "
                        "else MOT15)")
    p.add_argument("--results", required=True, help="frame, id, x, y, w, h, ... per line")
    p.add_argument("--similarity", choices=("iou", "centroid"), default="iou")
    p.add_argument("--threshold", type=fraction, default=0.5, help="match threshold in (0, 1] (default 0.5)")
    p.add_argument("--json", action="store_true")
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    for argument, path, kind in (("--gt", Path(args.gt) / "gt" / "gt.txt", "a sequence folder with gt/gt.txt"),
                                 ("--results", Path(args.results), "a results file")):
        if not path.is_file():
            raise UsageError(argument, f"{str(path)!r} not found; expected {kind}")
    from mtt_sim.metrics import PRINTED
    from mtt_sim.real import motchallenge

    if args.dry_run:  # the files read and checked as the scoring reads them, nothing scored
        recording, _ = motchallenge.read_scored(args.gt, args.results, args.benchmark)
        dry_run(args, estimate("eval", [(len(recording), "frames scored")], unit="frames scored"))
        return 0
    s = scenario.ScoringConfig()
    metrics = motchallenge.evaluate_results(args.gt, args.results, benchmark=args.benchmark, similarity=args.similarity,
                                            threshold=args.threshold, zero_distance=s.zero_distance,
                                            gospa_c=s.gospa_c, gospa_p=s.gospa_p)
    summary = {k: metrics[k] for k in PRINTED}
    if args.json:
        print(json.dumps(summary))
        return 0
    print_summary(summary)
    return 0
