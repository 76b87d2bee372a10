"""`mtt-sim run`: one episode with a tracker (or several side by side), its metrics, a video, a results file."""

from __future__ import annotations

import json

from mtt_sim.cli.arguments import (CONFIG_HELP, FORCE_HELP, SCENARIO_HELP, UsageError, add_dry_run,
                                   add_overrides, dry_run, episode_overrides, estimate, integer, loaded, output_file,
                                   print_summary, replaced, scenario_key, tracker_spec, tracker_specs)


def add(subparsers) -> None:
    p = subparsers.add_parser("run", help="run one episode with a tracker and print its metrics")
    p.add_argument("scenario", type=scenario_key, help=SCENARIO_HELP)
    p.add_argument("--tracker", type=tracker_spec,  # default: sort, parsed in run() unless --compare stands in
                   help="tracker spec, e.g. sort or 'sort:max_age=3,min_hits=1' (default: sort)")
    p.add_argument("--seed", type=integer(0), default=0, help="episode seed, >= 0 (default 0)")
    p.add_argument("--steps", type=integer(1), default=None, help="at most this many steps (default: the "
                                                                    "scenario's env.max_steps)")
    p.add_argument("--video", help="write an annotated video: .mp4 (H.264) or .gif")
    p.add_argument("--compare", type=tracker_specs,
                   help="several trackers on the same episode, one video panel each, side by side (comma-separated "
                        "specs, or ';'-separated: 'sort;jpda:coast=false')")
    p.add_argument("--scale", type=integer(1, 8), default=1, help="enlarge the video's frames this many "
                                                                    "times (1 to 8; for small scenes)")
    p.add_argument("--results", help="write the tracks as a MOTChallenge results file (.txt; an offline method's "
                                     "offline output)")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    add_overrides(p, CONFIG_HELP)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    overrides = episode_overrides(args)
    loaded([args.scenario], overrides)
    video = output_file(args.video, args.force, "--video", (".mp4", ".gif"))
    results = output_file(args.results, args.force, "--results", (".txt",))
    if args.compare and args.results:
        raise UsageError("--results", "a results file takes one tracker: leave out --compare")
    if args.scale != 1 and not args.video:
        raise UsageError("--scale", f"{args.scale}: enlarges the video's frames; give --video too")
    specs = args.compare or [args.tracker or tracker_spec("sort")]
    if dry_run(args, estimate("run", [(len(specs), "trackers"), (1, "seeds")], [args.scenario], overrides,
                              steps=args.steps)):
        return 0
    from mtt_sim.lab import experiment
    from mtt_sim.metrics import PRINTED

    records = experiment.run_episodes(args.scenario, specs, args.seed, overrides, video=args.video, steps=args.steps,
                                      progress=True, scale=args.scale, results=args.results)
    for record in records:
        metrics = record["metrics"] or {"metrics": "none: the sequence has no gt/gt.txt"}
        summary = {"scenario": str(args.scenario), "tracker": record["tracker"], "seed": args.seed,
                   **{k: metrics[k] for k in PRINTED if k in metrics}, **({} if record["metrics"] else metrics),
                   "tracker_fps": record["tracker_fps"], "env_fps": record["env_fps"]}
        if args.json:
            print(json.dumps(summary))
            continue
        print_summary(summary)
    if args.json:
        return 0
    for name, path in (("video", video), ("results", results)):
        if path:
            print(f"{name:12s} {path}" + replaced(args.force))
    return 0
