"""`mtt-sim list` and `mtt-sim trackers`: what there is to run, scenarios and trackers."""

from __future__ import annotations

from mtt_sim.sim import scenario


def add(subparsers) -> None:
    subparsers.add_parser("list", help="scenarios with their env ids and one-line descriptions").set_defaults(
        func=run_list)
    p = subparsers.add_parser("trackers", help="trackers with their descriptions and parameters (default, allowed "
                                               "values); installed plugins included")
    p.add_argument("names", nargs="*", metavar="TRACKER",
                   help="only these: registered names, or your own as module:Class or path/to/file.py:Class")
    p.set_defaults(func=run_trackers)


def run_list(args) -> int:
    from mtt_sim import env_ids

    ids = env_ids()
    for key, desc in scenario.available().items():
        print(f"{key:14s} {ids[key]:26s} {desc}")
    print(f"{'<folder>':14s} {'mtt_sim/Replay-v0':26s} a recorded MOTChallenge sequence (gym.make(..., sequence=folder); "
          "any command takes its folder)")
    return 0


def run_trackers(args) -> int:
    from mtt_sim import trackers

    for name in args.names or trackers.base.available():
        cls = trackers.base.tracker_class(name)
        print(f"{name}: {cls.description}")
        for line in trackers.base.describe(name):
            print("    " + line)
    return 0
