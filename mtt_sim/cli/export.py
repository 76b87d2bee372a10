"""`mtt-sim export`: write an episode as a MOTChallenge sequence (frames, ground truth, detections)."""

from __future__ import annotations

from mtt_sim.cli.arguments import (CONFIG_HELP, SCENARIO_HELP, add_dry_run, add_overrides, dry_run, episode_overrides,
                                   estimate, integer, loaded, output_folder, print_fields, scenario_key)


def add(subparsers) -> None:
    p = subparsers.add_parser("export", help="write an episode as a MOTChallenge sequence (frames, gt, detections)")
    p.add_argument("scenario", type=scenario_key, help=SCENARIO_HELP)
    p.add_argument("--out", required=True, help="the sequence folder to write")
    p.add_argument("--seed", type=integer(0), default=0, help="episode seed, >= 0 (default 0)")
    p.add_argument("--steps", type=integer(1), default=None, help="at most this many frames (default: env.max_steps)")
    p.add_argument("--force", action="store_true", help="write into a folder that is not empty (its old frames go)")
    add_overrides(p, CONFIG_HELP)
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    overrides = episode_overrides(args)
    loaded([args.scenario], overrides)
    out = output_folder(args.out, args.force, "--out", "replace its sequence")
    if dry_run(args, estimate("export", [(1, "episodes")], [args.scenario], overrides, steps=args.steps)):
        return 0
    from mtt_sim.lab.export import export_episode

    print_fields(export_episode(args.scenario, out, args.seed, args.steps, overrides, progress=True))
    return 0
