"""`mtt-sim advise`: the label-free route in one command. For a camera with detections and no labels: fit its scene,
tune each candidate tracker on it, and print them ranked, each with its tuned spec (ready for --tracker), its score and
spread over fresh seeds of the scene, and what the route is worth on real cameras of this kind."""

from __future__ import annotations

import json
import shlex
import sys
from pathlib import Path

from mtt_sim.cli import resuming
from mtt_sim.cli.arguments import (FORCE_HELP, UsageError, add_dry_run, announce, check_sensor, dry_run,
                                   episode_frames, estimate, integer, output_file, parse_seeds, replaced,
                                   tracker_specs)
from mtt_sim.cli.fit_scene import add_camera
from mtt_sim.cli.tune import metric_goals


def add(subparsers) -> None:
    from mtt_sim.lab.advise import CANDIDATES, FRAMES

    p = subparsers.add_parser("advise", help="for a camera without labels: fit its scene, tune each candidate tracker "
                                             "on it and rank them, with the tuned specs and the simulator's confidence")
    add_camera(p)
    p.add_argument("--trackers", type=tracker_specs, default=list(CANDIDATES),
                   help=f"the candidates, each tuned from its spec (default {','.join(CANDIDATES)})")
    p.add_argument("--metric", type=metric_goals, default="HOTA", help="what to rank by and tune for (default HOTA)")
    p.add_argument("--trials", type=integer(1), default=20, help="trials a candidate, the defaults' first (default 20)")
    episodes = p.add_mutually_exclusive_group()
    episodes.add_argument("--frames", type=integer(1), default=FRAMES,
                          help=f"about this many frames a trial: the scene runs as many seeds (default {FRAMES})")
    episodes.add_argument("--seeds", type=parse_seeds,
                          help="the scene's episode seeds instead: a count, a list or a range")
    p.add_argument("--seed", type=integer(0), default=0, help="the samplers' seed: one seed, one advice (default 0)")
    p.add_argument("--scene", help="also write the fitted scene (.toml)")
    p.add_argument("--out", help="write the ranking as Markdown (.md); its journal beside it lets --resume go on")
    p.add_argument("--json", action="store_true", help="print the ranking as one JSON object")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    resuming.add(p, "--out")
    add_dry_run(p)
    p.set_defaults(func=run)


def run(args) -> int:
    if "," in args.metric:
        raise UsageError("--metric", f"{args.metric!r}: advise ranks by one metric, e.g. HOTA")
    force = resuming.force(args, args.out, "--out")
    out = output_file(args.out, force, "--out", (".md",))
    scene_file = output_file(args.scene, args.force, "--scene", (".toml",))
    check_sensor(args.sensor)
    from mtt_sim.lab.advise import FRESH, fresh_count, seeds_for
    from mtt_sim.lab.confirm import CONTENDERS

    synthetic = {"sensor.model": "synthetic"}
    args.seeds = args.seeds or seeds_for(episode_frames(args.folder, synthetic), args.frames)
    # the trials, then at most the contenders and the defaults on the fresh seeds
    episodes = args.trials * len(args.seeds) + (CONTENDERS + 1) * fresh_count(args.seeds)
    work = estimate("advise", [(len(args.trackers), "trackers"), (episodes, "episodes")], [args.folder], synthetic)
    if dry_run(args, work + ", after the scene's fit"):
        return 0
    announce(work)
    from mtt_sim.lab import advise, routes
    from mtt_sim.sim2real import fit_scene

    definition = {"folder": str(Path(args.folder).resolve()), "sensor": Path(args.sensor).read_text(),
                  "trackers": args.trackers, "metric": args.metric, "trials": args.trials, "seeds": args.seeds,
                  "seed": args.seed, "scored on": f"fresh seeds, at least {FRESH}"}
    journal = resuming.journal(out, definition, args.resume, "candidates") if out else None
    say = (lambda line: print(line, file=sys.stderr, flush=True))
    path = scene_file or Path(out or ".").with_name(f".advise_{Path(args.folder).name}_scene.toml")
    try:
        text = journal.get("scene", None) if journal else None
        if text is None:
            say(f"advise: fitting the scene of {Path(args.folder).name}")
            text = fit_scene.fit_scene(args.folder, args.sensor, seeds=())[3]
            if journal:
                journal.put("scene", text)
        path.write_text(text)
        choices = advise.advise(str(path), args.trackers, args.metric, args.trials, args.seeds, args.seed,
                                done=(lambda spec: journal.get(("tracker", spec), None)) if journal else None,
                                finished=(lambda spec, c: journal.put(("tracker", spec), c)) if journal else None,
                                say=say)
    except KeyboardInterrupt:
        if journal:
            return resuming.stopped("advise", journal, "the scene and the candidates tuned")
        raise
    finally:
        if not scene_file:
            path.unlink(missing_ok=True)
    camera = routes.camera_kind(text)
    report = _report(args, choices, camera)
    if out:
        out.write_text(report + "\n")
        journal.finish()
    if args.json:
        print(json.dumps({"camera": camera, "metric": args.metric, "choices": [advise.as_dict(c) for c in choices],
                          "warnings": advise.warnings(choices, camera)}))
    else:
        print(report)
        for p, what in ((out, "ranking"), (scene_file, "scene")):
            if p:
                print(f"{what}: {p}" + replaced(args.force))
    return 0


def _report(args, choices, camera: str) -> str:
    """The ranking, the warnings and the command that runs the first choice on the camera."""
    from mtt_sim.lab import advise

    lines = [f"# Trackers for {Path(args.folder).name} ({camera} camera), ranked on its fitted scene", "",
             advise.table(choices, args.metric), ""]
    warnings = [f"- warning: {w}" for w in advise.warnings(choices, camera)]
    lines += warnings + [""] * bool(warnings)
    lines += [f"Run the first: mtt-sim run {shlex.quote(args.folder)} --tracker {shlex.quote(choices[0].spec)}"]
    return "\n".join(lines)
