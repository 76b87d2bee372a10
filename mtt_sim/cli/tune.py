"""`mtt-sim tune`: an Optuna study of a tracker's parameters on scenarios, scenario files or sequence folders."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from mtt_sim.cli.arguments import (CONFIG_HELP, FORCE_HELP, INTERRUPTED, UsageError, add_dry_run, add_overrides, announce,
                                   dry_run, episode_overrides, estimate, integer, loaded, output_file, parse_seeds,
                                   replaced, require, scenario_keys, tracker_spec)


def metric_goals(text: str) -> str:
    """The --metric text, checked: metric names in any case, each with an optional + or - for its direction."""
    from mtt_sim.metrics.goals import goals

    try:
        return ",".join(g.text for g in goals(text))
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def add(subparsers) -> None:
    p = subparsers.add_parser("tune", help="tune a tracker's parameters (Optuna, TPE) on scenarios or sequences: the "
                                           "best spec, its score beside the defaults', the best trials")
    p.add_argument("spec", type=tracker_spec, help="the tracker spec to start from; parameters given in it stay fixed "
                                                   "(lmb:reid=false)")
    p.add_argument("--on", type=scenario_keys, required=True, metavar="SOURCE[,SOURCE...]",
                   help="scenarios, scenario files or sequence folders; the score is the mean over them and the seeds")
    p.add_argument("--metric", type=metric_goals, default="HOTA",
                   help="what to optimise (default HOTA); several for a Pareto front, e.g. HOTA,-IDSW (counts of "
                        "errors and distances are minimised unless marked +)")
    p.add_argument("--trials", type=integer(1), default=50,
                   help="finished trials in all, the defaults' first; an interrupted one does not count (default 50)")
    p.add_argument("--seeds", type=parse_seeds, default=parse_seeds("1"),
                   help="episode seeds per source: a count (3: seeds 0..2), a list or a range (default 1)")
    p.add_argument("--seed", type=integer(0), default=0, help="the sampler's seed: one seed, one study (default 0)")
    p.add_argument("--confirm", type=integer(0), default=0, metavar="N",
                   help="then run the study's best 3 specs and the defaults on N fresh seeds of the simulated sources, "
                        "and keep the best there: a score the study's own seeds did not choose (default 0: none)")
    p.add_argument("--workers", type=integer(1), default=1, help="processes running a trial's episodes (default 1)")
    p.add_argument("--backend", choices=("local", "ray"), default="local",
                   help="local processes, or Ray tasks for a trial's episodes (the [ray] extra; --address for a cluster)")
    p.add_argument("--address", help="with --backend ray: a Ray cluster's address")
    p.add_argument("--storage", help="an Optuna storage URL, e.g. sqlite:///study.db: the study is kept there and "
                                     "resumed by the same command (interrupted trials rerun first)")
    p.add_argument("--study-name", help="the study's name in --storage (default: the tracker, the sources, the metric "
                                        "and a digest of all that defines the tuning); a stored study made for "
                                        "another tuning is refused")
    p.add_argument("--time-budget", type=integer(1), metavar="SECONDS", help="stop starting trials after this long")
    p.add_argument("--out", help="write the result as TOML: the spec, its score, the defaults' and the parameters")
    p.add_argument("--plot", help="write the optimisation history as a PNG, and the parameters' importances beside "
                                  "it (<name>_importances.png; the [plot] extra)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    add_overrides(p, CONFIG_HELP)
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    require("optuna", "tune", "tune")
    overrides = episode_overrides(args)
    loaded(args.on, overrides)
    out = output_file(args.out, args.force, "--out", (".toml",))
    plot = output_file(args.plot, args.force, "--plot", (".png",))
    if plot:
        require("matplotlib", "--plot", "plot")
    if args.backend == "ray":
        require("ray", "--backend", "ray")
    elif args.address:
        raise UsageError("--address", f"{args.address!r}: a Ray cluster's address goes with --backend ray")
    trials = [(args.trials, "trials"), (len(args.on), "sources"), (len(args.seeds), "seeds")]
    work = estimate("tune", trials, args.on, overrides)
    if args.confirm:
        from mtt_sim.lab.confirm import CONTENDERS

        fresh = _fresh(args.on, overrides)
        work += (f", then its best {CONTENDERS} and the defaults on {args.confirm} fresh seeds (at most "
                 f"{(CONTENDERS + 1) * args.confirm * fresh} episodes)")
    if dry_run(args, work):
        return 0
    announce(work)
    _caution(args.spec, args.on, overrides, args.confirm)
    from mtt_sim.lab import tune

    try:
        result, study = tune.tune(args.spec, args.on, args.metric, args.trials, args.seeds, overrides, args.seed,
                                  args.workers, args.storage, args.study_name, args.time_budget,
                                  progress=not args.json, backend=args.backend, address=args.address,
                                  confirm_seeds=args.confirm, say=lambda line: print(line, file=sys.stderr))
    except tune.Interrupted as stop:  # Ctrl-C or SIGTERM: the trial in flight marked interrupted, the best so far
        if stop.result is None:
            print("mtt-sim tune: interrupted before any trial finished" + _resume(args, stop.study.study_name),
                  file=sys.stderr)
            return INTERRUPTED
        result, study = stop.result, stop.study
    except tune.NoTrialFinished as err:  # every trial failed (or was pruned): why, in one line, and no result
        print(f"mtt-sim tune: error: {err}", file=sys.stderr)
        return 1
    if out:
        out.write_text(result.toml())
    if plot:
        tune.plot(study, result.goals, plot)
    if args.json:
        print(json.dumps(result.as_dict()))
    else:
        print(tune.report(result, study))
        for path, what in ((out, "result"), (plot, "plots")):
            if path:
                print(f"{what}: {path}" + (f" and {Path(path).stem}_importances.png" if what == "plots" else "")
                      + replaced(args.force))
    if result.interrupted:
        print(f"mtt-sim tune: interrupted; {result.finished} of {result.wanted} trials finished"
              + _resume(args, result.study), file=sys.stderr)
        return INTERRUPTED
    return 0


def _caution(spec: str, sources: list[str], overrides: dict, confirm: int) -> None:
    """Warn, once per route, where tuning the tracker of `spec` in simulation has not held on real video
    (`routes.RECORD`), and name --confirm where it is not given: on the shared sequences it took the scene route's
    worst loss away (docs/tuning.md, "Fresh seeds")."""
    from mtt_sim.lab import routes
    from mtt_sim.trackers import TrackerSpec

    tracker = TrackerSpec.of(spec).registered
    taken = {routes.route_of(source, overrides) for source in sources} - {None}
    lines = sorted(filter(None, {routes.caution(*route, tracker) for route in taken}))
    for line in lines:
        print(f"mtt-sim tune: warning: {line}", file=sys.stderr)
    if lines and not confirm:
        print("mtt-sim tune: note: a study's best is flattered by its own seeds; --confirm 4 runs its best specs and "
              "the defaults on 4 fresh seeds and keeps the best there", file=sys.stderr)


def _fresh(sources: list[str], overrides: dict) -> int:
    """How many sources --confirm runs again; none (every source a sequence scored on its own detections) is an
    error."""
    from mtt_sim.lab.confirm import simulated

    count = len(simulated(sources, overrides))
    if not count:
        raise UsageError("--confirm", "every source is a recorded sequence on its own detections, the same episode "
                                      "whatever the seed: there is nothing to confirm (fresh seeds need a scenario, "
                                      "a scenario file or a sequence's twin, --detector synthetic)")
    return count


def _resume(args, study: str) -> str:
    """How an interrupted study goes on: the same command, where --storage keeps it."""
    if args.storage:
        return f"; the same command resumes study {study!r}"
    return "; the study was in memory only (--storage keeps one to resume)"
