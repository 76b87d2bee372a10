"""Every `mtt-sim ...` command the README and docs/*.md quote runs as written: each is run through `mtt_sim.cli.main`
with --dry-run (every argument checked as a run checks it; nothing runs or is written) in a scratch folder that sees
the checkout's files, and must exit 0.

Found: the lines of fenced code blocks (joined over trailing backslashes, `# comments` dropped, shell variables set in
the page such as T="..." expanded; an optional [--flag] given) and inline code spans, from the word mtt-sim followed by a subcommand up to
the end of the shell command (&&, |, ;, >). Skipped, each for a reason the test keeps: placeholders (DIR, FILE, SPEC,
SEQ, <...>, [scenario], ..., path/to, an unset $VARIABLE), the shared data (../shared/data), and inputs that an earlier step of the page writes
and the checkout does not hold (seq/, results.txt, policy.npz, mine.py): a dry run writes nothing for a later line to
read. `list`, `trackers` and `config` take no --dry-run (they are instant and write nothing): they run as written.
"""

import argparse
import os
import re
import shlex
from pathlib import Path

import pytest

from helpers import exit_code
from mtt_sim import cli

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
INSTANT = ("list", "trackers", "config")
PLACEHOLDER = re.compile(r"\bDIR\b|\bFILE\b|\bSPEC\b|\bSEQ\b|<|(?:^|\s)\[|\.\.\.|path/to|\.\./shared|\$")
OPTIONAL = re.compile(r"\s\[(--[\w-]+)\]")  # an optional flag shown as [--json]: run with it
OUTPUTS = {"--out", "--video", "--plot", "--results", "--results-dir"}  # what a command writes: need not exist
COMMANDS = set(next(a for a in cli.build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices)


def _commands_in(text: str):
    """(line number, command text) of every mtt-sim command quoted in a page's code blocks and inline code."""
    found, in_block, block_vars, pending, start = [], False, {}, "", 0
    lines = text.splitlines()
    for number, line in enumerate(lines, 1):
        if line.lstrip().startswith("```"):
            in_block, pending = not in_block, ""  # a variable set in one block holds for the page's later ones
            continue
        if in_block:
            if not pending:
                start = number
            pending += line.rstrip()
            if pending.endswith("\\"):
                pending = pending[:-1] + " "
                continue
            whole, pending = pending, ""
            assignment = re.fullmatch(r"\s*([A-Za-z_]\w*)=(.*)", whole)
            if assignment:
                try:
                    block_vars[assignment[1]] = shlex.split(assignment[2])[0] if assignment[2].strip() else ""
                except ValueError:
                    pass
                continue
            for name, value in block_vars.items():
                whole = whole.replace(f'"${name}"', shlex.quote(value)).replace(f"${name}", shlex.quote(value))
            found += [(start, c) for c in _from_mtt_sim(whole, shell=True)]
    for match in re.finditer(r"(?<!`)`(mtt-sim [^`]+)`(?!`)", text):
        commands = _from_mtt_sim(" ".join(match[1].split()), False)
        found += [(text[: match.start()].count("\n") + 1, c) for c in commands if len(c.split()) > 2]  # not a name
    return found


def _from_mtt_sim(line: str, shell: bool) -> list[str]:
    """The mtt-sim commands of one shell line (a code block's: comments dropped) or an inline code span."""
    out = []
    for part in re.split(r"\s(?:&&|\|\||\||;)\s", line):
        part = part.split(" #")[0] if shell else part
        words = part.split()
        if "mtt-sim" in words:
            rest = words[words.index("mtt-sim") + 1:]
            if rest and rest[0] in COMMANDS:
                out.append(part[part.index("mtt-sim"):].split(" > ")[0].strip())
    return out


def _skipped(argv: list[str]) -> str | None:
    """Why a command is not run, or None."""
    text = " ".join(argv)
    if PLACEHOLDER.search(text):
        return "a placeholder"
    previous = None
    for word in argv[1:]:
        if previous not in OUTPUTS and not word.startswith("-"):
            for piece in re.split(r"[,;]", word):  # lists of sources, tracker specs with a file in a parameter
                for candidate in (piece.split(":")[0], piece.split("=")[-1].split(":")[0]):
                    looks_like_path = "/" in candidate or re.search(r"\.(txt|npz|toml|py|csv|json)$", candidate)
                    if looks_like_path and not (ROOT / candidate).exists():
                        return f"reads {candidate}, which is not in the checkout (an earlier step writes it)"
        previous = word
    return None


def _documented():
    cases = []
    for page in PAGES:
        for line, command in _commands_in(page.read_text()):
            try:
                argv = shlex.split(OPTIONAL.sub(r" \1", command))[1:]
            except ValueError:
                argv = None
            cases.append(pytest.param(argv, command, id=f"{page.name}:{line}:{command[:60]}"))
    return cases


DOCUMENTED = _documented()


def test_the_pages_quote_commands_of_every_kind():
    names = {argv[0] for argv, _ in (c.values for c in DOCUMENTED) if argv}
    assert len(DOCUMENTED) > 60 and {"run", "bench", "sweep", "tune", "stress", "export", "eval"} <= names


@pytest.mark.parametrize("argv, command", DOCUMENTED)
def test_a_documented_command_runs_as_written(argv, command, tmp_path, monkeypatch, capsys):
    assert argv, f"not a shell command: {command}"
    why = _skipped(argv)
    if why:
        pytest.skip(why)
    for entry in ROOT.iterdir():  # the checkout's files at hand (docs/experiments/..., scenarios/), nothing of it written
        if entry.name not in (".git", ".venv"):
            (tmp_path / entry.name).symlink_to(entry)
    monkeypatch.chdir(tmp_path)
    code = exit_code(argv if argv[0] in INSTANT else [*argv, "--dry-run"])
    captured = capsys.readouterr()
    assert code == 0, f"{command}\n{captured.err}"
    assert sorted(os.listdir(tmp_path)) == sorted(e.name for e in ROOT.iterdir() if e.name not in (".git", ".venv"))


def test_a_wrong_command_in_a_page_is_found_and_fails(tmp_path, monkeypatch, capsys):
    page = ("Shake it:\n\n```\nT=\"sort;sort:cmc=sparse_flow\"\nmtt-sim sweep mot17_like --param render.shake=0,8 \\\n"
            "    --trackers \"$T\"   # two trackers\n```\n\nor `mtt-sim run mot17_like --config "
            "render.camera=shake,render.shake=8`, and `mtt-sim bench` by name.\n")
    found = [c for _, c in _commands_in(page)]
    assert [shlex.split(c) for c in found] == [
        ["mtt-sim", "sweep", "mot17_like", "--param", "render.shake=0,8", "--trackers", "sort;sort:cmc=sparse_flow"],
        ["mtt-sim", "run", "mot17_like", "--config", "render.camera=shake,render.shake=8"]]
    monkeypatch.chdir(tmp_path)
    assert cli.main([*shlex.split(found[0])[1:], "--dry-run"]) == 0
    assert cli.main([*shlex.split(found[1])[1:], "--dry-run"]) == 2
    assert "render.camera = 'shake,render.shake=8'" in capsys.readouterr().err
