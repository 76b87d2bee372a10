"""`mtt-sim motion`: how the people of sequences and scenarios move, and how camera traces move, side by side, so that
a simulated world is held against real ones by the same numbers."""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

from mtt_sim.cli.arguments import (CONFIG_HELP, FORCE_HELP, add_dry_run, add_overrides, dry_run, episode_overrides,
                                   estimate, integer, loaded, output_file, replaced, scenario_key)

STILL = 3e-4  # a trace whose image centre moves a median share of the width below this is a still camera's


def trace_file(text: str) -> str:
    """A camera trace in BoT-SORT's GMC format, read whole (a bad row is named)."""
    from mtt_sim.sim.camera import read_warps

    try:
        read_warps(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None
    return text


def image_size(text: str) -> tuple[int, int]:
    """WIDTHxHEIGHT in pixels, e.g. 1920x1080."""
    width, sep, height = text.lower().partition("x")
    if not (sep and width.isdigit() and height.isdigit() and int(width) > 0 and int(height) > 0):
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT in pixels, e.g. 1920x1080, got {text!r}")
    return int(width), int(height)


def add(subparsers) -> None:
    p = subparsers.add_parser("motion", help="how people move in sequences and scenarios (speed, deviation from "
                                             "constant velocity, standing, turning, time in view) and how camera "
                                             "traces move, side by side")
    p.add_argument("sources", nargs="*", type=scenario_key, metavar="SOURCE",
                   help="sequence folders (their ground truth), scenario keys or .toml files (one episode each)")
    p.add_argument("--trace", nargs="+", default=[], type=trace_file, metavar="FILE",
                   help="camera traces in BoT-SORT's GMC format (a line a frame: index, then a 2x3 warp)")
    p.add_argument("--trace-size", type=image_size, default=(1920, 1080), metavar="WxH",
                   help="the traces' image size, for the translation as a share of the width (default 1920x1080)")
    p.add_argument("--seed", type=integer(0), default=0, help="the scenarios' episode seed (default 0)")
    p.add_argument("--steps", type=integer(1), help="cut each scenario's episode to this many frames")
    p.add_argument("--plot", help="write the speed and deviation distributions as a PNG (the [plot] extra)")
    p.add_argument("--fit", metavar="FILE.toml",
                   help="fit the walking model to the ground truth of the sequence folders among the sources ([walk]) "
                        "and the camera to the --trace files ([render]), and write them as TOML tables")
    p.add_argument("--json", action="store_true", help="print the statistics as one JSON object")
    p.add_argument("--force", action="store_true", help=FORCE_HELP)
    add_dry_run(p)
    add_overrides(p, CONFIG_HELP + " (for the scenarios; a sequence's own people are measured as they are)")
    p.set_defaults(func=run)


def run(args) -> int:
    from mtt_sim.cli.arguments import UsageError, require

    if not args.sources and not args.trace:
        raise UsageError("SOURCE", "give sequence folders or scenarios, or --trace files, or both")
    overrides = episode_overrides(args)
    from mtt_sim.real.layout import is_sequence
    from mtt_sim.sim.camera import read_warps
    from mtt_sim.sim2real import motion

    for source in args.sources:
        loaded([source], motion.overrides_for(source, overrides))
    plot = output_file(args.plot, args.force, "--plot", (".png",))
    if plot:
        require("matplotlib", "--plot", "plot")
    fit = output_file(args.fit, args.force, "--fit", (".toml",))
    real = [s for s in args.sources if is_sequence(s)]
    if fit and not real and not args.trace:
        raise UsageError("--fit", "fits the walking model to real ground truth and the camera to traces: give "
                                  "sequence folders (with gt/gt.txt) among the sources, or --trace files")
    traces = {t: read_warps(t) for t in args.trace}
    trace_cameras = {t: motion.camera(w, *args.trace_size) for t, w in traces.items()}
    still = [c["translation median (width)"] < STILL for c in trace_cameras.values()]
    if fit and len(set(still)) > 1:
        raise UsageError("--fit", "the traces mix still cameras (" + ", ".join(t for t, s in zip(args.trace, still) if s)
                         + ") and moving ones: fit each kind apart")
    if dry_run(args, estimate("motion", [(len(args.sources), "episodes")], args.sources, overrides, steps=args.steps)
               if args.sources else f"motion: {len(args.trace)} traces read"):
        return 0

    people, windows, cameras, truths = {}, {}, {}, []
    for source in args.sources:
        warps = []
        frames, frame_rate, size = motion.scored_frames(source, overrides, args.seed, args.steps, warps)
        name = Path(source).stem if source.endswith(".toml") else Path(source).name
        people[name] = motion.people(frames, frame_rate)
        windows[name] = motion.window_values(frames, frame_rate)
        if warps:  # a simulated scene's own camera
            cameras[name] = motion.camera(warps, *size)
        if source in real:
            truths.append((frames, frame_rate))
    cameras.update({Path(t).stem: c for t, c in trace_cameras.items()})
    if plot:
        motion.plot(windows, plot)
    if fit:
        tables = _fitted(truths, [(w, *args.trace_size) for w in traces.values()], any(still))
        from mtt_sim.sim import scenario

        fit.write_text(scenario.to_toml(tables, ["fitted by mtt-sim motion --fit to " + ", ".join(
            Path(s).name for s in [*real, *args.trace])]))
    if args.json:
        print(json.dumps({"people": people, "cameras": cameras}))
        return 0
    for title, table in (("people (one-second windows, in body heights)", people), ("cameras (per frame)", cameras)):
        if table:
            print(f"{title}\n\n{motion.markdown(table)}\n")
    if plot:
        print(f"plot: {plot}" + replaced(args.force))
    if fit:
        keys = [f"{table}.{k}={json.dumps(v)}" for table, values in tables.items() for k, v in values.items()]
        print(f"fitted: {fit}" + replaced(args.force) + f" ({' and '.join(f'[{t}]' for t in tables)}); a scene takes "
              f"them as its own tables, or as --config {' '.join(keys)}")
    return 0



def _fitted(truths: list, traces: list, still: bool) -> dict:
    """The [walk] table fitted to real ground truth, (frames, frame rate) each, and the [render] camera keys fitted
    to traces, (warps, width, height) each: the still camera's where they are `still`, else the walking camera's."""
    from mtt_sim.sim import camera
    from mtt_sim.sim2real import fit_walkers

    tables = {}
    if truths:
        tables["walk"] = dataclasses.asdict(fit_walkers.fit(truths))
    if traces:
        tables["render"] = {"camera": "still" if still else "walking", **camera.fit(traces, still=still)}
    return tables
