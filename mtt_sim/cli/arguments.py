"""What the commands share: the argument types (each raises with what is allowed), the checks of what the arguments
name together, raised as a UsageError before any work starts, and the summary printer.

Light on purpose: the simulator and the trackers are imported inside the functions that need them, so that a
mistyped argument is answered at once.
"""

from __future__ import annotations

import argparse
import configparser
import dataclasses
import importlib.util
import math
import os
import sys
import tomllib
from pathlib import Path
from typing import Sequence

from mtt_sim import sources
from mtt_sim.real.layout import is_sequence
from mtt_sim.sim import scenario
from mtt_sim.core.settings import SensorConfig, table

MAX_SEEDS = 100_000  # more is a typo (0-99999999), not a grid anyone means to run
INTERRUPTED = 130  # the shell's status for a command stopped by Ctrl-C (SIGTERM is treated the same way)
SCENARIO_HELP = ("scenario key (see `mtt-sim list`, any case), env id (mtt_sim/Crossing-v0), .toml file or a "
                 "MOTChallenge sequence folder")
CONFIG_HELP = "overrides, e.g. sensor.clutter_rate=5 groups.0.count=10"
FORCE_HELP = "replace an existing output"


class UsageError(Exception):
    """An argument that passed parsing but cannot be used (a file that exists, an override the scenario rejects)."""

    def __init__(self, argument: str, message: str):
        super().__init__(f"argument {argument}: {message}")


# ------------------------------------------------------------------ argument types (each raises with what is allowed)

def integer(lo: int, hi: int | None = None):
    """An integer type of at least lo (and at most hi)."""
    allowed = f"an integer >= {lo}" if hi is None else f"an integer in {lo}..{hi}"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be {allowed}, got {text!r}") from None
        if value < lo or (hi is not None and value > hi):
            raise argparse.ArgumentTypeError(f"must be {allowed}, got {text!r}")
        return value

    return parse


def fraction(text: str) -> float:
    """A number in (0, 1]."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value <= 1:
        raise argparse.ArgumentTypeError(f"must be a number in (0, 1], got {text!r}")
    return value


def number(lo: float | None = None, hi: float | None = None, lo_open: bool = True):
    """A finite number type above lo (or at least lo, with lo_open=False) and at most hi."""
    allowed = "a number" + (f" {'>' if lo_open else '>='} {lo:g}" if lo is not None else "") + \
        (f" and <= {hi:g}" if hi is not None else "")

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = float("nan")
        if not math.isfinite(value) or (lo is not None and (value <= lo if lo_open else value < lo)) or \
                (hi is not None and value > hi):
            raise argparse.ArgumentTypeError(f"must be {allowed}, got {text!r}")
        return value

    return parse


def parse_seeds(text: str) -> list[int]:
    """Seeds from a count ("5": 0..4), a list ("3,7,11"), a range ("100-199") or a list of both ("0-4,9")."""
    text = text.strip()
    try:
        if text.isdigit():
            count = int(text)
            if count < 1:
                raise ValueError
            if count > MAX_SEEDS:
                raise OverflowError
            return list(range(count))
        seeds = []
        for item in text.split(","):
            first, sep, last = item.strip().partition("-")
            lo, hi = int(first), int(last) if sep else int(first)
            if lo < 0 or hi < lo:
                raise ValueError
            if len(seeds) + hi - lo + 1 > MAX_SEEDS:
                raise OverflowError
            seeds += range(lo, hi + 1)
    except OverflowError:
        raise argparse.ArgumentTypeError(f"{text!r}: at most {MAX_SEEDS} seeds") from None
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a count of at least 1 (5: seeds 0..4), a list (3,7,11) or "
                                         "a range (100-199) of seeds >= 0") from None
    if len(set(seeds)) != len(seeds):
        raise argparse.ArgumentTypeError(f"{text!r}: a seed is given twice")
    return seeds


def scenario_key(text: str) -> str:
    """A scenario as the loader names it (a key, an env id, a .toml file or a sequence folder), as a `SourceSpec` that
    reads it once; a .toml file is read whole here, so that a mistyped key in it is named with the file (not blamed on
    --config)."""
    try:
        found = sources.SourceSpec(text, canonical=True)
        if str(found).endswith(".toml"):
            found.scenario()
        return found
    except scenario.ConfigError as err:
        raise argparse.ArgumentTypeError(str(err)) from None
    except (OSError, UnicodeDecodeError) as err:
        raise argparse.ArgumentTypeError(f"{text!r}: cannot be read ({err})") from None


def scenario_keys(text: str) -> list[str]:
    """Distinct comma-separated scenarios."""
    keys = [scenario_key(t) for t in text.split(",") if t.strip()]
    if not keys or len(set(keys)) != len(keys):
        raise argparse.ArgumentTypeError(f"{text!r}: expected distinct comma-separated scenarios")
    return keys


def tracker_specs(text: str) -> list[str]:
    """Distinct tracker specs, each parsed and checked once (`TrackerSpec`: the tracker its check built is the first
    its episodes use), a registered tracker named as registered."""
    from mtt_sim import trackers

    specs = trackers.split_specs(text)
    if not specs or len(set(specs)) != len(specs):
        raise argparse.ArgumentTypeError(f"{text!r}: expected distinct tracker specs, e.g. sort,iou or "
                                         "'sort:min_hits=1,max_age=5;iou'")
    try:
        return [trackers.TrackerSpec(spec, canonical=True) for spec in specs]
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def tracker_spec(text: str) -> str:
    """One tracker spec."""
    specs = tracker_specs(text)
    if len(specs) != 1:
        raise argparse.ArgumentTypeError(f"{text!r}: one tracker spec, e.g. 'sort:max_age=3,min_hits=1'")
    return specs[0]


def calibration_folder(text: str) -> str:
    """A real sequence folder with both a ground truth and detections (what calibrate and validate compare)."""
    folder = Path(text)
    missing = [f for f in ("gt/gt.txt", "det/det.txt") if not (folder / f).is_file()]
    if not folder.is_dir() or missing:
        raise argparse.ArgumentTypeError(f"{text!r} is not a sequence folder with gt/gt.txt and det/det.txt"
                                         + (f" (no {missing[0]})" if folder.is_dir() else ""))
    for name in ("det/det.txt", "gt/gt.txt"):
        rows_in(folder / name, "argument DIR")
    sequence_read(text)
    return text


def distinct_folders(folders: list[str], argument: str = "DIR") -> None:
    """Each sequence folder once (a folder given twice would count its data twice)."""
    seen = {}
    for folder in folders:
        key = os.path.realpath(folder)
        if key in seen:
            raise UsageError(argument, f"{folder!r} is given twice" + (f" (as {seen[key]!r} too)" if seen[key] != folder
                                                                       else "") + "; give each sequence once")
        seen[key] = folder


def rows_in(path: Path, argument: str) -> None:
    """A MOTChallenge file with at least one row, or an ArgumentTypeError naming it."""
    try:
        with open(path, "rb") as f:
            empty = not any(line.strip() for line in f)
    except OSError as err:
        raise argparse.ArgumentTypeError(f"{str(path)!r} cannot be read ({err.strerror})") from None
    if empty:
        raise argparse.ArgumentTypeError(f"{str(path)!r} has no rows: nothing to fit to or compare with")


def sequence_read(folder: str) -> None:
    """The sequence folder's files read as a run reads them (rows, frames, seqinfo.ini), or an ArgumentTypeError with
    the file and row."""
    from mtt_sim.real.sequence import Recording

    try:
        Recording(folder)
    except ValueError as err:  # ConfigError too
        raise argparse.ArgumentTypeError(str(err)) from None


def metric_names(text: str) -> list[str]:
    """Comma-separated metrics, any case, as the metrics name them."""
    from mtt_sim.metrics import METRICS, PER_TARGET

    names = {m.lower(): m for m in (*METRICS, *PER_TARGET)}
    out = []
    for typed in filter(None, (t.strip() for t in text.split(","))):
        if typed.lower() not in names:
            import difflib

            near = difflib.get_close_matches(typed.lower(), names, n=1)
            raise argparse.ArgumentTypeError(f"unknown metric {typed!r}" + (f" (did you mean {names[near[0]]!r}?)"
                                             if near else "") + f"; available: {', '.join(names.values())}")
        out.append(names[typed.lower()])
    if not out or len(set(out)) != len(out):
        raise argparse.ArgumentTypeError(f"{text!r}: expected one or more distinct metrics, e.g. MOTA,IDF1")
    return out


def toml_value(text: str):
    """A value as TOML reads it (numbers, booleans, lists), else the text itself."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


# ------------------------------------------------------------------ the overrides

def add_overrides(parser: argparse.ArgumentParser, config_help: str) -> None:
    """--config, and the detector's two shortcuts: --detector (sensor.model) and --sensor (a [sensor] table file)."""
    parser.add_argument("--config", nargs="*", default=[], metavar="KEY=VALUE", help=config_help)
    parser.add_argument("--detector", choices=("synthetic", "foreground", "recorded"),
                        help="sensor.model: on a sequence folder, 'synthetic' replays its ground truth through the "
                             "synthetic detector (its twin) instead of det/det.txt ('recorded', the default there)")
    parser.add_argument("--sensor", metavar="FILE.toml",
                        help="the [sensor] table of this file (e.g. from mtt-sim calibrate) as overrides; --config wins")


def parse_overrides(items: list[str]) -> dict:
    """`key=value` strings to a dotted-key dict; values are read as TOML (numbers, booleans, lists), else as text."""
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise UsageError("--config", f"{item!r}: expected key=value, e.g. sensor.clutter_rate=5")
        if key in out:
            raise UsageError("--config", f"{key} is given twice ({key}={out[key]!r}, then {item!r}); give it once")
        out[key] = toml_value(value)
    return out


@dataclasses.dataclass(frozen=True)
class _SensorFile:
    """What a --sensor file holds: one [sensor] table (checked key by key as a scenario's)."""

    sensor: SensorConfig = table(SensorConfig, "the detector")


def check_sensor(path: str) -> dict:
    """The --sensor file's [sensor] table, every key and value checked before any work (a UsageError names the
    problem)."""
    try:
        sensor = scenario.read_sensor(path)
        scenario.from_mapping(sensor, path, _SensorFile)
    except scenario.ConfigError as err:
        raise UsageError("--sensor", str(err)) from None
    return sensor


def episode_overrides(args) -> dict:
    """The episode's overrides: --sensor's [sensor] table, then --detector's model, then --config (the last wins)."""
    out = {}
    if args.sensor:
        out.update({f"sensor.{k}": v for k, v in check_sensor(args.sensor)["sensor"].items()})
    if args.detector:
        out["sensor.model"] = args.detector
    out.update(parse_overrides(args.config))
    return out


# ------------------------------------------------------------------ checks of what the arguments name together

def loaded(scenarios: list[str], config: dict, argument: str = "--config", configs=({},)) -> None:
    """Every scenario loads with the overrides (and each swept value), or a UsageError names the problem (a
    `SourceSpec` keeps what it read for the run)."""
    for sc in scenarios:
        for extra in configs:
            try:
                sources.open_source(sc, {**config, **extra})
            except scenario.ConfigError as err:
                try:
                    sources.open_source(sc)
                except scenario.ConfigError as own:  # the source itself, whatever the overrides: its file names it
                    raise own from None
                raise UsageError(argument, str(err)) from None


def output_file(path: str | None, force: bool, argument: str, suffixes: tuple[str, ...]) -> Path | None:
    """An output file that can be written: a known suffix, an existing writable folder, not there yet unless --force."""
    if path is None:
        return None
    out = Path(path)
    if out.suffix.lower() not in suffixes:
        raise UsageError(argument, f"{path!r}: the file name must end in {' or '.join(suffixes)}")
    if out.is_dir():
        raise UsageError(argument, f"{path!r} is a folder; give a file name")
    if out.exists() and not force:
        raise UsageError(argument, f"{path!r} exists; add --force to replace it")
    _writable_folder(out.parent, argument, path)
    return out


def output_folder(path: str, force: bool, argument: str, forced: str) -> Path:
    """An output folder that can be written: new, empty, or (with --force, which does what `forced` says) not."""
    out = Path(path)
    if out.exists() and (not out.is_dir() or any(out.iterdir())) and not force:
        raise UsageError(argument, f"{path!r} exists and is not empty; add --force to {forced}")
    _writable_folder(out if out.is_dir() else out.parent, argument, path)
    return out


def _writable_folder(folder: Path, argument: str, path: str) -> None:
    if not folder.is_dir():
        raise UsageError(argument, f"{path!r}: folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK):
        raise UsageError(argument, f"{path!r}: folder {str(folder)!r} is not writable")


def require(module: str, argument: str, extra: str) -> None:
    """The module an option needs is installed, or a UsageError says which extra brings it."""
    try:
        found = importlib.util.find_spec(module) is not None
    except ValueError:  # a module set to None in sys.modules
        found = False
    if not found:
        raise UsageError(argument, f"needs {module}: pip install 'mtt-sim[{extra}]'")


# ------------------------------------------------------------------ the estimate of the work, and --dry-run

DRY_RUN_HELP = "check every argument as a run would, print an estimate of the work and stop: nothing runs or is written"


def add_dry_run(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--dry-run", action="store_true", help=DRY_RUN_HELP)


def episode_frames(source: str, overrides: dict | None = None, steps: int | None = None) -> int:
    """The frames of one episode of `source` with `overrides`, cheaply: a scenario's env.max_steps (its file read, no
    world built), a sequence's length as its `SourceSpec` read it (or, named by a plain path, its seqinfo.ini's
    seqLength), at most `steps`."""
    overrides = overrides or {}
    if not is_sequence(source):
        frames = sources.SourceSpec.of(source).scenario(overrides).env.max_steps
        return frames if steps is None else min(frames, steps)
    length = source.length() if isinstance(source, sources.SourceSpec) else None
    if length is None:
        ini = configparser.ConfigParser()
        ini.optionxform = str
        try:
            length = int(ini["Sequence"]["seqLength"]) if ini.read(Path(source) / "seqinfo.ini") else None
        except (KeyError, ValueError, configparser.Error):
            length = None
    if length is None:
        length = sources.open_source(source, overrides).length
    limit = scenario.expand_dotted(overrides).get("env", {}).get("max_steps")
    frames = length if limit is None else min(length, limit)
    return frames if steps is None else min(frames, steps)


def estimate(command: str, factors: Sequence[tuple[int, str]], sources_: Sequence[str] = (),
             overrides: dict | None = None, configs: Sequence[dict] = ({},), steps: int | None = None,
             unit: str = "episodes") -> str:
    """One line of the work a command is about to do, e.g. 'bench: 2 trackers x 3 scenarios x 5 seeds = 30 episodes,
    about 9000 frames': the product of `factors` (count, plural noun), and where `sources_` are given the frames, each
    episode as long as the mean episode of the sources under each of `configs` (see `episode_frames`)."""
    total = math.prod(n for n, _ in factors)
    counted = [f"{n} {_noun(n, what)}" for n, what in factors]
    line = f"{command}: " + (f"{' x '.join(counted)} = " if len(factors) > 1 or factors[0][1] != unit else "") + \
        f"{total} {_noun(total, unit)}"
    if sources_:
        lengths = [episode_frames(s, {**(overrides or {}), **c}, steps) for s in sources_ for c in configs]
        line += f", about {round(total * sum(lengths) / len(lengths))} frames"
    return line


def _noun(n: int, plural: str) -> str:
    return plural[:-1] if n == 1 and plural.endswith("s") else plural


def announce(line: str) -> None:
    """The estimate of a long run, on stderr as it starts (stdout and --json stay clean)."""
    print(line, file=sys.stderr, flush=True)


def dry_run(args, line: str) -> bool:
    """With --dry-run, the estimate `line` printed (stdout) and True: the command stops there; else False (a long run
    then says it with `announce` once its last check has passed)."""
    if getattr(args, "dry_run", False):
        print(line)
    return bool(getattr(args, "dry_run", False))


# ------------------------------------------------------------------ what the commands print

def replaced(force: bool) -> str:
    """The note after a written output's path: --force may have replaced an older one."""
    return " (replaced)" if force else ""


def print_summary(summary: dict) -> None:
    """One metric a line: floats to 3 decimals, "-" for a measure with no value (no occlusion decided, say)."""
    for k, v in summary.items():
        print(f"{k:17s} {v:.3f}" if isinstance(v, float) else f"{k:17s} {'-' if v is None else v}")


def print_fields(summary: dict) -> None:
    """One field of a command's summary a line, as it comes."""
    for k, v in summary.items():
        print(f"{k:12s} {v}")
