"""`mtt-sim check-real`: hold sort, bytetrack and the scoring against real MOTChallenge data and the reference
codes' outputs."""

from __future__ import annotations

from pathlib import Path

from mtt_sim.cli.arguments import UsageError, add_dry_run, dry_run, estimate


def add(subparsers) -> None:
    p = subparsers.add_parser("check-real", help="hold sort, bytetrack and the scoring against real MOTChallenge data "
                                                 "and the reference codes' outputs")
    p.add_argument("data", help="the shared data folder (mot15/, reference/, mot17/, mot17_results/)")
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    if not (Path(args.data) / "mot15").is_dir():
        raise UsageError("data", f"{args.data!r}: expected the shared data folder (with mot15/, reference/, mot17/)")
    sequences = sorted(str(p) for p in (Path(args.data) / "mot15").iterdir() if p.is_dir())
    if not sequences:
        raise UsageError("data", f"{args.data!r}: mot15/ holds no sequence folder")
    if dry_run(args, estimate("check-real", [(3, "trackers"), (len(sequences), "MOT15 sequences")], sequences)):
        return 0
    from mtt_sim.sim2real import check

    return 0 if check.check(args.data) else 1
