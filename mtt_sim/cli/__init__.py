"""The `mtt-sim` command: list scenarios and trackers, run an episode, bench and sweep trackers, measure speed, print
the configuration, learn the re-identification metric, write and score MOTChallenge files.

One module a command, each with add(subparsers), its arguments, and the function it runs. Every argument is checked
before any work starts; a bad one gets one line naming the argument, the value and what is allowed, and exit status 2.
The heavy modules (the simulator, the trackers) are imported only once the arguments hold.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys

from mtt_sim import __version__

from mtt_sim.cli import (advise, bench, calibrate, check_real, config, docs, evaluate, export, fit_scene, learn_policy,
                         learn_reid, listing, motion, perf, run, stress, sweep, tune, validate)
from mtt_sim.cli.arguments import INTERRUPTED, UsageError
from mtt_sim.core.moved import moved

__all__ = ["build_parser", "main"]
# deprecated: the keys a summary prints are the metric families' declarations, mtt_sim.metrics.PRINTED
__getattr__ = moved(__name__, "mtt_sim.metrics", SUMMARY_KEYS="PRINTED")
COMMANDS = (listing, run, bench, sweep, stress, tune, fit_scene, advise, learn_policy, perf, learn_reid, export, evaluate,
            check_real, calibrate, validate, motion, docs, config)  # the order of `mtt-sim --help`


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: the problem and where to read more, not the whole usage block."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """The top-level parser with every command's subparser, in the order of COMMANDS."""
    p = _Parser(prog="mtt-sim", description="A Gymnasium environment for video multi-target tracking.")
    p.add_argument("--version", action="version", version=f"mtt-sim {__version__}")
    subparsers = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for command in COMMANDS:
        command.add(subparsers)
    return p


def _terminated(signum, frame):
    raise KeyboardInterrupt  # SIGTERM stops a run as Ctrl-C does: workers stopped, finished records kept


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    previous = signal.signal(signal.SIGTERM, _terminated)
    try:
        return args.func(args)
    except UsageError as err:
        print(f"mtt-sim {args.command}: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"mtt-sim {args.command}: interrupted", file=sys.stderr)
        return INTERRUPTED
    except BrokenPipeError:  # the reader went away (`mtt-sim trackers | head`): nothing left to say
        sys.stdout = open(os.devnull, "w")
        return 0
    except (ValueError, OSError, ImportError) as err:  # what the arguments could not foresee: a file, a missing extra
        print(f"mtt-sim {args.command}: error: {err}", file=sys.stderr)
        return 2
    finally:
        signal.signal(signal.SIGTERM, previous)
