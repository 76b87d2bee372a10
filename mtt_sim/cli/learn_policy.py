"""`mtt-sim learn-policy`: learn the `learned` tracker's report / keep policy from the score, by CMA-ES."""

from __future__ import annotations

import argparse
import math
import shutil
from pathlib import Path

from mtt_sim.cli import resuming
from mtt_sim.cli.arguments import (
    CONFIG_HELP,
    FORCE_HELP,
    UsageError,
    add_dry_run,
    add_overrides,
    announce,
    dry_run,
    episode_overrides,
    estimate,
    integer,
    loaded,
    number,
    output_file,
    parse_seeds,
    require,
    scenario_keys,
)


def add(subparsers) -> None:
    p = subparsers.add_parser("learn-policy", help="learn which of a base tracker's candidate tracks to report and "
                                                   "keep, from the score (CMA-ES; the `learned` tracker)")
    p.add_argument("--on", type=scenario_keys, required=True, metavar="SOURCE[,SOURCE...]",
                   help="scenarios, scenario files, sequence folders (twins with --detector synthetic)")
    p.add_argument("--seeds", type=parse_seeds, default=parse_seeds("1000-1003"),
                   help="training episodes per simulated source: a count, list or range (default 1000-1003, away from "
                        "the experiments' 0..9)")
    p.add_argument("--frames", type=integer(1), help="cut each training episode to this many frames")
    p.add_argument("--base", type=base_name, default="sort",
                   help="the tracker whose association proposes the candidates: sort or bytetrack (default sort)")
    p.add_argument("--generations", type=integer(1), default=20, help="CMA-ES generations (default 20)")
    p.add_argument("--population", type=integer(4), help="policies a generation (default: CMA-ES's for 30 weights, 14)")
    p.add_argument("--sigma", type=number(0), default=1.0,
                   help="CMA-ES's first step size on the weights, a number > 0 (default 1)")
    p.add_argument("--metrics", default="MOTA,HOTA", help="the fitness: the mean of these metrics (default MOTA,HOTA)")
    p.add_argument("--seed", type=integer(0), default=0, help="one seed, one policy (default 0)")
    p.add_argument("--workers", type=integer(1), default=1, help="processes running a generation's episodes (default 1)")
    p.add_argument("--out", default="policy.npz", help="where to write the policy (default policy.npz)")
    p.add_argument("--plot", help="write the learning curve as a PNG (the [plot] extra)")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    resuming.add(p, "--out")
    add_overrides(p, CONFIG_HELP)
    add_dry_run(p)
    p.set_defaults(func=run)


def base_name(text: str) -> str:
    from mtt_sim.trackers.parts.management import BASES

    if text not in BASES:
        raise argparse.ArgumentTypeError(f"{text!r}: allowed: {', '.join(BASES)}")
    return text


def run(args) -> int:
    from mtt_sim.learn.policy_search import learn_policy
    from mtt_sim.metrics.goals import goals
    from mtt_sim.trackers.learned import save_policy

    overrides = episode_overrides(args)
    loaded(args.on, overrides)
    try:
        metrics = [g.metric for g in goals(args.metrics)]
    except ValueError as err:
        raise UsageError("--metrics", str(err)) from None
    lower = [g.metric for g in goals(args.metrics) if not g.maximize]
    if lower:
        raise UsageError("--metrics", f"{', '.join(lower)}: the fitness is a mean of scores where higher is better "
                                      "(MOTA, IDF1, HOTA, ...)")
    force = resuming.force(args, args.out, "--out")
    out = output_file(args.out, force, "--out", (".npz",))
    plot = output_file(args.plot, force, "--plot", (".png",))
    if plot:
        require("matplotlib", "--plot", "plot")
    population = args.population or 4 + int(3 * math.log(30))  # CMA-ES's own for the policy's 30 weights
    work_done = [(args.generations, "generations"), (population, "policies"), (len(args.on), "sources"),
                 (len(args.seeds), "seeds")]
    work_line = estimate("learn-policy", work_done, args.on, overrides, steps=args.frames)
    if dry_run(args, work_line):
        return 0
    definition = {"command": "learn-policy", "on": args.on, "seeds": list(args.seeds), "frames": args.frames,
                  "base": args.base, "population": args.population, "sigma": args.sigma, "metrics": metrics,
                  "seed": args.seed, "config": overrides}  # not --generations: a resumed search may go on for more
    journal = resuming.journal(out, definition, args.resume, "episodes")
    announce(work_line)
    work = Path(f"{out}.work")  # the training episodes and the policies tried, until the search ends
    try:
        learning = learn_policy(args.on, args.seeds, args.generations, args.population, args.sigma, args.seed,
                                args.workers, metrics, overrides, args.frames, progress=True, base=args.base,
                                work=work, journal=journal)
    except KeyboardInterrupt:
        return resuming.stopped("learn-policy", journal, f"the episodes replayed (and {work})")
    journal.finish()
    shutil.rmtree(work)
    save_policy(out, learning.weights, trained_on=",".join(args.on), seeds=str(list(args.seeds)), base=args.base,
                metrics=",".join(metrics), generations=str(args.generations), seed=str(args.seed))
    print(f"fitness (mean {'/'.join(metrics)} over {learning.episodes} episodes): SORT's rules {learning.start_fitness:.4f}, "
          f"learned {learning.fitness:.4f}")
    print(f"wrote {out}: use it with --tracker 'learned:policy={out}" + (f",base={args.base}'" if args.base != "sort"
                                                                           else "'"))
    if plot:
        from mtt_sim.lab.plots import learning_curve

        learning_curve(learning, plot)
        print(f"wrote {plot}")
    return 0
