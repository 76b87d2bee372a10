"""The `mtt-sim` command: list scenarios, run an episode, measure speed, print the config reference."""

from __future__ import annotations

import argparse
import json
import sys
import tomllib

import numpy as np

from . import perf, scenario
from .env import TrackingEnv
from .overlay import VideoWriter

ECHO_NOTE = ("The agent is a trivial built-in one that echoes each frame's detections as tracks, numbered afresh "
             "every frame (no tracker yet): a floor for trackers, with many identity switches.")


def parse_overrides(items: list[str]) -> dict:
    """`key=value` strings to a dotted-key dict; values are read as TOML (numbers, booleans, lists), else as text."""
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise scenario.ConfigError(f"--config {item!r}: expected key=value, e.g. sensor.clutter_rate=5")
        try:
            out[key] = tomllib.loads(f"v = {value}")["v"]
        except tomllib.TOMLDecodeError:
            out[key] = value
    return out


SUMMARY_KEYS = ("MOTA", "MOTP", "IDF1", "HOTA", "DetA", "AssA", "LocA", "GOSPA", "TP", "FP", "FN", "IDSW", "Frag",
                "MT", "PT", "ML", "num_frames", "num_gt_dets", "num_gt_ids")


def cmd_run(args) -> int:
    env = TrackingEnv(args.scenario, config=parse_overrides(args.config), render_mode="rgb_array" if args.video else None)
    obs, _ = env.reset(seed=args.seed)
    steps = args.steps or env.scenario.env.max_steps
    writer = VideoWriter(args.video, (env.scenario.render.width, env.scenario.render.height)) if args.video else None
    total = 0.0
    for _ in range(steps):
        n = int(obs["num_detections"])
        action = {"ids": np.arange(n), "boxes": obs["detections"][:n, :4]}
        if writer:
            env._remember(*env.validate_action(action))
            writer.write(env.render())
        obs, reward, terminated, truncated, _ = env.step(action)
        total += reward
        if terminated or truncated:
            break
    if writer:
        writer.close()
    summary = {"scenario": args.scenario, "seed": args.seed, "agent": "echo", "return": total,
               **{k: v for k, v in env.metrics.summary().items() if k in SUMMARY_KEYS}}
    if args.json:
        print(json.dumps(summary))
    else:
        print(ECHO_NOTE)
        for k, v in summary.items():
            print(f"{k:12s} {v:.3f}" if isinstance(v, float) else f"{k:12s} {v}")
        if args.video:
            print(f"{'video':12s} {args.video}")
    return 0


def cmd_list(args) -> int:
    from . import env_ids
    ids = env_ids()
    for key, desc in scenario.available().items():
        print(f"{key:14s} {ids[key]:26s} {desc}")
    return 0


def cmd_perf(args) -> int:
    print(perf.report(perf.measure(repeats=args.repeats, steps=args.steps)))
    print()
    print(perf.report_metrics(perf.measure_metrics(repeats=args.repeats)))
    return 0


def cmd_config(args) -> int:
    if args.scenario:
        print(json.dumps(scenario.to_mapping(scenario.load(args.scenario, parse_overrides(args.config))), indent=2))
    else:
        print(scenario.reference_table())
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="mtt-sim", description="A Gymnasium environment for video multi-target tracking.")
    sub = p.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="scenarios with their env ids and one-line descriptions").set_defaults(func=cmd_list)
    run = sub.add_parser("run", help="run one episode and print a summary", description="Run one episode. " + ECHO_NOTE)
    run.add_argument("scenario", help="scenario key (see `mtt-sim list`) or a .toml file")
    run.add_argument("--seed", type=int, default=0)
    run.add_argument("--steps", type=int, default=0, help="at most this many steps (default: the scenario's env.max_steps)")
    run.add_argument("--video", help="write an annotated video (.mp4 or .avi)")
    run.add_argument("--config", nargs="*", default=[], metavar="KEY=VALUE", help="overrides, e.g. sensor.clutter_rate=5")
    run.add_argument("--json", action="store_true", help="print the summary as JSON")
    run.set_defaults(func=cmd_run)
    pf = sub.add_parser("perf", help="env steps/s and metrics cost at 20 and 200 targets, each against a same-run reference")
    pf.add_argument("--repeats", type=int, default=5)
    pf.add_argument("--steps", type=int, default=200)
    pf.set_defaults(func=cmd_perf)
    cf = sub.add_parser("config", help="the configuration reference, or one scenario's resolved configuration")
    cf.add_argument("scenario", nargs="?")
    cf.add_argument("--config", nargs="*", default=[], metavar="KEY=VALUE")
    cf.set_defaults(func=cmd_config)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (scenario.ConfigError, OSError) as err:
        print(f"mtt-sim: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
