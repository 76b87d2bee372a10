"""`mtt-sim stress`: search a scenario's keys for the scenes where a tracker does worst, or loses most to another."""

from __future__ import annotations

import argparse
import json
import shlex
import sys

from mtt_sim.cli import resuming
from mtt_sim.cli.arguments import (CONFIG_HELP, FORCE_HELP, UsageError, add_dry_run, add_overrides,
                                   announce, dry_run, episode_overrides, estimate, integer, loaded, output_folder, parse_seeds,
                                   replaced, require, scenario_key, tracker_spec)

SAMPLERS = ("tpe", "cmaes", "random")


def dimensions(text: str) -> list:
    """--vary's comma-separated KEY=LO:HI and KEY=A|B items, each checked against the key's own range or choices."""
    from mtt_sim.lab import stress
    from mtt_sim.core.settings import ConfigError

    items = [t.strip() for t in text.split(",") if t.strip()]
    try:
        found = [stress.dimension(t) for t in items]
    except ConfigError as err:
        raise argparse.ArgumentTypeError(str(err)) from None
    keys = [d.key for d in found]
    if not found or len(set(keys)) != len(keys):
        raise argparse.ArgumentTypeError(f"{text!r}: expected distinct keys, e.g. sensor.clutter_rate=0:10,"
                                         "groups.0.count=5:30,render.camera=static|shake")
    return found


def scenario_to_vary(text: str) -> str:
    """A scenario key or .toml file: what has keys to vary (a recorded sequence has none to search)."""
    from mtt_sim.real.layout import is_sequence

    if is_sequence(text):
        raise argparse.ArgumentTypeError(f"{text!r} is a sequence folder: stress varies a scenario's keys, so it takes "
                                         "a scenario key or a .toml file (a sequence's twin is tuned with mtt-sim tune "
                                         "and checked with mtt-sim validate)")
    return scenario_key(text)


def add(subparsers) -> None:
    p = subparsers.add_parser("stress", help="search scenario keys for the scenes that break a tracker (Optuna): the "
                                             "worst scenes as runnable files, stills and videos")
    p.add_argument("spec", type=tracker_spec, help="the tracker under test, e.g. sort or 'lmb:reid=false'")
    p.add_argument("--scenario", type=scenario_to_vary, required=True,
                   help="a scenario key or .toml file to vary (not a sequence folder: it has no keys to vary)")
    p.add_argument("--vary", type=dimensions, required=True, metavar="KEY=LO:HI[,KEY=A|B ...]",
                   help="the keys searched: numbers between LO and HI, or some of a key's choices (a key alone: all "
                        "of them), within the key's own range; e.g. sensor.clutter_rate=0:10,render.camera=static|shake")
    p.add_argument("--objective", default="-MOTA",
                   help="what to make as large as possible: a metric of the tracker (--objective=-MOTA, IDSW, FN; "
                        "write a leading minus after '='), or arithmetic "
                        "over metrics, METRIC[spec] for another tracker on the same world: 'MOTA[sort] - MOTA[lmb]' "
                        "finds where lmb loses most to sort (default -MOTA)")
    p.add_argument("--budget", type=integer(1), default=30, help="scenes evaluated (default 30)")
    p.add_argument("--seeds", type=parse_seeds, default=parse_seeds("1"),
                   help="episode seeds per scene, a count, a list or a range; a scene's value is its worst seed's "
                        "(default 1: seed 0)")
    p.add_argument("--seed", type=integer(0), default=0, help="the sampler's seed: one seed, one search (default 0)")
    p.add_argument("--workers", type=integer(1), default=1, help="processes running a scene's episodes (default 1)")
    p.add_argument("--sampler", choices=SAMPLERS, default="tpe",
                   help="tpe (multivariate TPE, the default), cmaes (CMA-ES) or random sampling")
    p.add_argument("--against-random", action="store_true",
                   help="also run random sampling with the same budget and seed, and plot both histories")
    p.add_argument("--top", type=integer(1), default=5, help="worst scenes reported and written (default 5)")
    p.add_argument("--out", help="a folder for the worst scenes (worst-<rank>.toml, .jpg, .mp4), table.md and "
                                 "history.png (the [plot] extra)")
    p.add_argument("--json", action="store_true", help="print the worst scenes as one JSON object")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    resuming.add(p, "--out")
    add_overrides(p, CONFIG_HELP + "; searched keys are set over them")
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    require("optuna", "stress", "tune")
    overrides = episode_overrides(args)
    loaded([args.scenario], overrides)
    out = output_folder(args.out, resuming.force(args, args.out, "--out"), "--out", "write into it") if args.out else None
    if out:
        require("matplotlib", "--out", "plot")
    from mtt_sim.lab import stress
    from mtt_sim.core.settings import ConfigError

    try:
        stress.check_bounds(args.scenario, args.vary, overrides)
    except ConfigError as err:
        raise UsageError("--vary", str(err)) from None
    try:
        objective = stress.Objective(args.objective, args.spec)
    except ValueError as err:
        raise UsageError("--objective", str(err)) from None
    scenes = [(args.budget * (2 if args.against_random else 1), "scenes"), (len(args.seeds), "seeds"),
              (len(objective.specs), "trackers")]
    work = estimate("stress", scenes, [args.scenario], overrides)
    if dry_run(args, work):
        return 0

    definition = {"command": "stress", "spec": args.spec, "scenario": args.scenario, "objective": args.objective,
                  "vary": [d.text() for d in args.vary], "budget": args.budget, "seeds": list(args.seeds),
                  "seed": args.seed, "sampler": args.sampler, "against_random": args.against_random, "config": overrides}
    journal = resuming.journal(out, definition, args.resume, "episodes") if out else None
    announce(work)

    def searched(sampler: str) -> stress.Search:
        return stress.search(args.spec, args.scenario, args.vary, args.objective, args.budget, args.seeds,
                             args.seed, args.workers, sampler, overrides, progress=not args.json, journal=journal)

    try:
        found = searched(args.sampler)
        random = searched("random") if args.against_random else None
    except KeyboardInterrupt:
        if not journal:
            raise
        return resuming.stopped("stress", journal, "the scenes evaluated")
    if not found.scenes:
        raise ValueError("every scene failed: " + "; ".join(sorted({f["error"] for f in found.failed})))
    if out:
        command = shlex.join(["mtt-sim", *(a for a in sys.argv[1:] if a != "--resume")])  # as if never stopped
        worst = stress.write(found, out, args.top, command, random)
        journal.finish()
    else:
        worst = [{"scenario": args.scenario, "config": found.config_of(s), "seed": s.seed, "value": s.value,
                  "metrics": s.metrics if len(found.objective.specs) > 1 else s.metrics[args.spec]}
                 for s in found.worst(args.top)]
    if args.json:
        summary = {"worst": worst, "evaluations": len(found.scenes) + len(found.failed), "failed": found.failed}
        if random:
            summary["random"] = {"worst_value": random.worst(1)[0].value if random.scenes else None,
                                 "worst_so_far": random.worst_so_far()}
        summary["worst_so_far"] = found.worst_so_far()
        print(json.dumps(summary))
        return 0
    print(stress.table(found, args.top))
    print(f"\n{args.objective}: worst {found.worst(1)[0].value:.4g} after {args.budget} scenes ({args.sampler})"
          + (f"; random sampling's {random.worst(1)[0].value:.4g}" if random and random.scenes else ""))
    for failure in found.failed:
        print(f"failed scene {failure['params']}: {failure['error']}")
    if out:
        print(f"worst scenes: {out}/worst-<rank>.toml, .jpg, .mp4; table.md; history.png" + replaced(args.force))
        print(f"again: mtt-sim run {worst[0]['scenario']} --tracker '{args.spec}' --seed {worst[0]['seed']}")
    return 0
