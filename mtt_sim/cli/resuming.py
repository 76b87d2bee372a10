"""--resume, for the long commands (bench, sweep, stress, learn-policy): a run writing an output keeps a journal of
what it finished beside it (`<out>.journal`, see mtt_sim.lab.journal), and the same command rerun with --resume
takes what the journal holds and runs only the rest, ending with the outputs an uninterrupted run writes."""

from __future__ import annotations

import sys
from pathlib import Path

from mtt_sim.cli.arguments import INTERRUPTED, UsageError


def add(parser, output: str) -> None:
    """The --resume flag of a command whose output is `output` (its option, e.g. --out)."""
    parser.add_argument("--resume", action="store_true",
                        help=f"finish an interrupted run of the same command and arguments: what it finished (kept "
                             f"in <{output.strip('-')}>.journal beside {output}) is taken as it was, only the rest runs")


def force(args, out: str | None, argument: str) -> bool:
    """Whether `out` may be replaced: with --force, or with --resume when an interrupted run's journal is beside it.
    --resume without an output, or with a finished one, and a run over an interrupted one's journal without either
    flag are refused with what to do."""
    if out is None:
        if args.resume:
            raise UsageError("--resume", f"needs {argument}: a run's journal is kept beside its output")
        return args.force
    from mtt_sim.lab.journal import path_beside

    journal, exists = path_beside(out), Path(out).exists()
    if args.resume and not journal.exists() and exists and not args.force:
        raise UsageError("--resume", f"{out!r} is a finished run's (no {journal} beside it): nothing to resume; add "
                                     "--force to run it again")
    if journal.exists() and not (args.resume or args.force):
        raise UsageError(argument, f"{out!r} is an interrupted run's ({journal} beside it): add --resume to finish "
                                   "it, or --force to start over")
    return args.force or args.resume


def journal(out, definition: dict, resume: bool, unit: str):
    """The journal beside `out` for a run defined by `definition`: read back with --resume (a run defined otherwise
    is refused, saying what differs), else started anew. What it kept is said in `unit` (episodes, scenes, ...)."""
    from mtt_sim.lab.journal import Journal, JournalMismatch, path_beside

    try:
        opened = Journal(path_beside(out), definition, resume)
    except JournalMismatch as err:
        raise UsageError("--resume", str(err)) from None
    if opened.resumed:
        print(f"resuming: {opened.resumed} finished {unit} kept from {opened.path}", file=sys.stderr)
    return opened


def stopped(command: str, journal, kept: str) -> int:
    """An interrupted run's end: its journal closed, one line on what `kept` holds and how to go on; status 130."""
    journal.close()
    print(f"mtt-sim {command}: interrupted; {kept} are kept in {journal.path}: the same command with --resume goes on "
          "from there", file=sys.stderr)
    return INTERRUPTED
