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
from .truth import Truth

ECHO_NOTE = ("The agent is a trivial built-in one that echoes each frame's detections as tracks, numbered afresh "
             "every frame (no tracker yet), so the figures describe the detector, not a tracker.")


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


def _iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    lo = np.maximum(a[:, None, :2], b[None, :, :2])
    hi = np.minimum(a[:, None, :2] + a[:, None, 2:], b[None, :, :2] + b[None, :, 2:])
    inter = np.prod(np.clip(hi - lo, 0, None), axis=2)
    union = np.prod(a[:, 2:], axis=1)[:, None] + np.prod(b[:, 2:], axis=1)[None] - inter
    return inter / np.maximum(union, 1e-12)


def _detector_counts(truth: Truth, rows: np.ndarray) -> tuple[int, int]:
    """(true positives, detections) with a greedy IoU >= 0.5 match, for the echo agent's summary."""
    if not len(truth) or not len(rows):
        return 0, len(rows)
    iou = _iou(truth.boxes, rows[:, :4])
    hits = 0
    while iou.size and iou.max() >= 0.5:
        i, j = np.unravel_index(np.argmax(iou), iou.shape)
        iou[i, :], iou[:, j] = 0, 0
        hits += 1
    return hits, len(rows)


def cmd_run(args) -> int:
    env = TrackingEnv(args.scenario, config=parse_overrides(args.config), render_mode="rgb_array" if args.video else None)
    obs, _ = env.reset(seed=args.seed)
    steps = args.steps or env.scenario.env.max_steps
    writer = VideoWriter(args.video, (env.scenario.render.width, env.scenario.render.height)) if args.video else None
    gt = tp = dets = frames = 0
    for _ in range(steps):
        n = int(obs["num_detections"])
        hits, count = _detector_counts(env.truth, obs["detections"][:n])
        gt, tp, dets, frames = gt + len(env.truth), tp + hits, dets + count, frames + 1
        action = {"ids": np.arange(n), "boxes": obs["detections"][:n, :4]}
        if writer:
            env._remember(*env.validate_action(action))
            writer.write(env.render())
        obs, _, terminated, truncated, _ = env.step(action)
        if terminated or truncated:
            break
    if writer:
        writer.close()
    summary = {"scenario": args.scenario, "seed": args.seed, "frames": frames, "gt_boxes": gt, "detections": dets,
               "detector_recall": tp / max(gt, 1), "detector_precision": tp / max(dets, 1),
               "births": env.world.births, "agent": "echo (detections as tracks)"}
    if args.json:
        print(json.dumps(summary))
    else:
        print(ECHO_NOTE)
        for k, v in summary.items():
            print(f"{k:20s} {v:.3f}" if isinstance(v, float) else f"{k:20s} {v}")
        if args.video:
            print(f"{'video':20s} {args.video}")
    return 0


def cmd_list(args) -> int:
    from . import env_ids
    ids = env_ids()
    for key, desc in scenario.available().items():
        print(f"{key:14s} {ids[key]:26s} {desc}")
    return 0


def cmd_perf(args) -> int:
    print(perf.report(perf.measure(repeats=args.repeats, steps=args.steps)))
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
    pf = sub.add_parser("perf", help="env steps per second at 20 and 200 targets, against an OpenCV drawing reference")
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
