"""The `mtt-sim` command: list scenarios and trackers, run an episode, bench and sweep trackers, measure speed, print
the configuration, learn the re-identification metric, write and score MOTChallenge files.

Every argument is checked before any work starts; a bad one gets one line naming the argument, the value and what is
allowed, and exit status 2. The heavy modules (the simulator, the trackers) are imported only once the arguments hold.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import shlex
import signal
import sys
import tomllib
from pathlib import Path

from mtt_sim import __version__

from mtt_sim.sim import scenario

SUMMARY_KEYS = ("MOTA", "MOTP", "IDF1", "HOTA", "DetA", "AssA", "LocA", "GOSPA", "CentreError", "TP", "FP", "FN", "IDSW",
                "Frag", "MT", "PT", "ML", "Occlusions", "Reacquired", "HiddenCentreError", "num_frames", "num_gt_dets",
                "num_gt_ids")
INTERRUPTED = 130  # the shell's status for a command stopped by Ctrl-C (SIGTERM is treated the same way)


class UsageError(Exception):
    """An argument that passed parsing but cannot be used (a file that exists, an override the scenario rejects)."""

    def __init__(self, argument: str, message: str):
        super().__init__(f"argument {argument}: {message}")


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors: the problem and where to read more, not the whole usage block."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


# ------------------------------------------------------------------ argument types (each raises with what is allowed)

def _integer(lo: int, hi: int | None = None):
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


def _fraction(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value <= 1:
        raise argparse.ArgumentTypeError(f"must be a number in (0, 1], got {text!r}")
    return value


def parse_seeds(text: str) -> list[int]:
    """Seeds from a count ("5": 0..4), a list ("3,7,11"), a range ("100-199") or a list of both ("0-4,9")."""
    text = text.strip()
    try:
        if text.isdigit():
            count = int(text)
            if count < 1:
                raise ValueError
            return list(range(count))
        seeds = []
        for item in text.split(","):
            first, sep, last = item.strip().partition("-")
            lo, hi = int(first), int(last) if sep else int(first)
            if lo < 0 or hi < lo:
                raise ValueError
            seeds += range(lo, hi + 1)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a count of at least 1 (5: seeds 0..4), a list (3,7,11) or "
                                         "a range (100-199) of seeds >= 0") from None
    if len(set(seeds)) != len(seeds):
        raise argparse.ArgumentTypeError(f"{text!r}: a seed is given twice")
    return seeds


def _scenario(text: str) -> str:
    try:
        return str(scenario.resolve(text))
    except scenario.ConfigError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _scenarios(text: str) -> list[str]:
    keys = [_scenario(t) for t in text.split(",") if t.strip()]
    if not keys or len(set(keys)) != len(keys):
        raise argparse.ArgumentTypeError(f"{text!r}: expected distinct comma-separated scenarios")
    return keys


def _tracker_specs(text: str) -> list[str]:
    from mtt_sim import trackers

    specs = trackers.split_specs(text)
    if not specs or len(set(specs)) != len(specs):
        raise argparse.ArgumentTypeError(f"{text!r}: expected distinct tracker specs, e.g. sort,iou or "
                                         "'sort:min_hits=1,max_age=5;iou'")
    canonical = []
    for spec in specs:
        try:
            name = trackers.make(spec).name
        except ValueError as err:
            raise argparse.ArgumentTypeError(str(err)) from None
        canonical.append(name + spec[len(spec.partition(":")[0]):])  # the name as registered, the parameters as typed
    return canonical


def _tracker_spec(text: str) -> str:
    specs = _tracker_specs(text)
    if len(specs) != 1:
        raise argparse.ArgumentTypeError(f"{text!r}: one tracker spec, e.g. 'sort:max_age=3,min_hits=1'")
    return specs[0]


def _calibration_folder(text: str) -> str:
    """A real sequence folder with both a ground truth and detections (what calibrate and validate compare)."""
    folder = Path(text)
    missing = [f for f in ("gt/gt.txt", "det/det.txt") if not (folder / f).is_file()]
    if not folder.is_dir() or missing:
        raise argparse.ArgumentTypeError(f"{text!r} is not a sequence folder with gt/gt.txt and det/det.txt"
                                         + (f" (no {missing[0]})" if folder.is_dir() else ""))
    return text


def _metrics(text: str) -> list[str]:
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
    return out


def parse_overrides(items: list[str]) -> dict:
    """`key=value` strings to a dotted-key dict; values are read as TOML (numbers, booleans, lists), else as text."""
    out = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise UsageError("--config", f"{item!r}: expected key=value, e.g. sensor.clutter_rate=5")
        out[key] = _toml_value(value)
    return out


def _overrides(args) -> dict:
    """The episode's overrides: --sensor's [sensor] table, then --detector's model, then --config (the last wins)."""
    out = {}
    if args.sensor:
        try:
            table = scenario.read_sensor(args.sensor)["sensor"]
        except scenario.ConfigError as err:
            raise UsageError("--sensor", str(err)) from None
        out.update({f"sensor.{k}": v for k, v in table.items()})
    if args.detector:
        out["sensor.model"] = args.detector
    out.update(parse_overrides(args.config))
    return out


def _toml_value(text: str):
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


# ------------------------------------------------------------------ checks of what the arguments name together

def _loaded(scenarios: list[str], overrides: dict, argument: str = "--config", configs=({},)) -> None:
    """Every scenario loads with the overrides (and each swept value), or a UsageError names the problem."""
    for sc in scenarios:
        for extra in configs:
            try:
                scenario.load(sc, {**overrides, **extra})
            except scenario.ConfigError as err:
                raise UsageError(argument, str(err)) from None


def _output(path: str | None, force: bool, argument: str, suffixes: tuple[str, ...]) -> Path | None:
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


def _writable_folder(folder: Path, argument: str, path: str) -> None:
    if not folder.is_dir():
        raise UsageError(argument, f"{path!r}: folder {str(folder)!r} does not exist")
    if not os.access(folder, os.W_OK):
        raise UsageError(argument, f"{path!r}: folder {str(folder)!r} is not writable")


def _require(module: str, argument: str, extra: str) -> None:
    try:
        found = importlib.util.find_spec(module) is not None
    except ValueError:  # a module set to None in sys.modules
        found = False
    if not found:
        raise UsageError(argument, f"needs {module}: pip install 'mtt-sim[{extra}]'")


# ------------------------------------------------------------------ commands

def cmd_run(args) -> int:
    overrides = _overrides(args)
    _loaded([args.scenario], overrides)
    video = _output(args.video, args.force, "--video", (".mp4", ".gif"))
    results = _output(args.results, args.force, "--results", (".txt",))
    if args.compare and args.results:
        raise UsageError("--results", "a results file takes one tracker: leave out --compare")
    specs = args.compare or [args.tracker]
    from mtt_sim.lab import experiment

    records = experiment.run_episodes(args.scenario, specs, args.seed, overrides, video=args.video, steps=args.steps,
                                      progress=True, scale=args.scale, results=args.results)
    for record in records:
        metrics = record["metrics"] or {"metrics": "none: the sequence has no gt/gt.txt"}
        summary = {"scenario": args.scenario, "tracker": record["tracker"], "seed": args.seed,
                   **{k: metrics[k] for k in SUMMARY_KEYS if k in metrics}, **({} if record["metrics"] else metrics),
                   "tracker_fps": record["tracker_fps"], "env_fps": record["env_fps"]}
        if args.json:
            print(json.dumps(summary))
            continue
        _print_summary(summary)
    if args.json:
        return 0
    for name, path in (("video", video), ("results", results)):
        if path:
            print(f"{name:12s} {path}" + (" (replaced)" if args.force else ""))
    return 0


def cmd_bench(args) -> int:
    from mtt_sim.metrics import PER_TARGET

    overrides = _overrides(args)
    _loaded(args.scenarios, overrides)
    if args.by == "target" and set(args.metric) - set(PER_TARGET):
        raise UsageError("--metric", f"with --by target: {', '.join(PER_TARGET)} (per-target metrics)")
    title = ",".join(args.scenarios) if args.by == "target" else ""
    _plot_output(args)
    if args.plot and args.by == "target":
        raise UsageError("--plot", "plots columns of scenarios: leave out --by target")

    def plot(records):
        from mtt_sim.lab import plots

        plots.bench_plot(records, args.metric, args.plot)
    return _grid(args, args.scenarios, overrides, None, lambda records, metric: _table(records, metric, args.by, title),
                 plot)


def cmd_sweep(args) -> int:
    key, sep, values = args.param.partition("=")
    if not sep or not key or not values:
        raise UsageError("--param", f"{args.param!r}: expected key=v1,v2,..., e.g. sensor.clutter_rate=0,5,10")
    values = [_toml_value(v) for v in values.split(",")]
    overrides = _overrides(args)
    _loaded([args.scenario], overrides)
    _loaded([args.scenario], overrides, "--param", [{key: v} for v in values])
    _plot_output(args)

    def table(records, metric) -> str:
        from mtt_sim.lab import experiment

        rows = experiment.summarize(records, metric, by="config")
        for r in rows:
            r["column"] = f"{key.split('.')[-1]}={json.loads(r['column'])[key]}"
        return experiment.markdown(rows, f"{args.scenario}, sweeping {key}") if rows else ""

    def plot(records):
        from mtt_sim.lab import plots

        plots.sweep_plot(records, args.scenario, key, values, args.metric, args.plot)
    return _grid(args, [args.scenario], overrides, [{key: v} for v in values], table, plot)


def _plot_output(args) -> None:
    """--plot's checks, before any work: matplotlib at hand, a file that can be written."""
    if args.plot:
        _require("matplotlib", "--plot", "plot")
        _output(args.plot, args.force, "--plot", (".png", ".pdf", ".svg"))


def _table(records, metric, by, title) -> str:
    from mtt_sim.lab import experiment

    rows = experiment.summarize(records, metric, by=by)
    return experiment.markdown(rows, title) if rows else ""


def _grid(args, scenarios: list[str], overrides: dict, configs, table, plot) -> int:
    """Run a bench or sweep grid: records written as they finish, a table(records, metric) per metric, with --plot
    plot(records) (one panel per metric), and the failed episodes at the end, and on Ctrl-C or SIGTERM the workers
    stopped and what finished kept. Exit status: 0, 1 if an episode failed, 130 if interrupted."""
    out = _output(args.out, args.force, "--out", (".csv", ".json"))
    if args.results_dir:
        folder = Path(args.results_dir)
        if folder.exists() and (not folder.is_dir() or any(folder.iterdir())) and not args.force:
            raise UsageError("--results-dir", f"{args.results_dir!r} exists and is not empty; add --force to write into it")
        _writable_folder(folder if folder.is_dir() else folder.parent, "--results-dir", args.results_dir)
    if args.backend == "ray":
        _require("ray", "--backend", "ray")
    from mtt_sim.lab import experiment

    finished = []
    record_file = experiment.RecordFile(out) if out else None

    def keep(record):
        finished.append(record)
        if record_file:
            record_file.append(record)

    interrupted = False
    try:
        records = experiment.run_grid(args.trackers, scenarios, args.seeds, config=overrides, configs=configs,
                                      workers=args.workers, progress=True, backend=args.backend, address=args.address,
                                      on_record=keep, results_dir=args.results_dir)
    except KeyboardInterrupt:
        records, interrupted = finished, True
    finally:
        if record_file:
            record_file.close()
    if out and not interrupted:
        experiment.write_records(records, out)  # again, in grid order
    done = [r for r in records if r is not None]
    print("\n\n".join(filter(None, (table(done, m) for m in args.metric))))
    scored = [r for r in done if r["metrics"] is not None]
    if args.plot and scored:
        plot(scored)
        print(f"\nplot: {args.plot} ({', '.join(args.metric)})" + (" (replaced)" if args.force else ""))
    failed = [r for r in done if r["error"]]
    if failed:
        print(f"\n{len(failed)} of {len(done)} episodes failed:")
        for r in failed:
            again = ["mtt-sim", "run", r["scenario"], "--tracker", r["tracker"], "--seed", str(r["seed"])]
            config = [f"{k}={json.dumps(v)}" for k, v in r["config"].items()]
            print(f"  {r['tracker']} on {r['scenario']} seed {r['seed']}: {r['error']}\n"
                  f"    again: {shlex.join(again + (['--config', *config] if config else []))}")
    if out:
        print(f"\nrecords: {out}" + (" (replaced)" if args.force else ""))
    if args.results_dir:
        print(f"results files: {args.results_dir}/<tracker>/<scenario>[-seed<k>].txt")
    if interrupted:
        print(f"mtt-sim {args.command}: interrupted; {len(done)} of {_grid_size(args, scenarios, configs)} episodes "
              "finished" + (f", their records in {out}" if out else ""), file=sys.stderr)
        return INTERRUPTED
    return 1 if failed else 0


def _grid_size(args, scenarios, configs) -> int:
    return len(args.trackers) * len(scenarios) * len(args.seeds) * len(configs or [{}])


def cmd_list(args) -> int:
    from mtt_sim import env_ids

    ids = env_ids()
    for key, desc in scenario.available().items():
        print(f"{key:14s} {ids[key]:26s} {desc}")
    print(f"{'<folder>':14s} {'mtt_sim/Replay-v0':26s} a recorded MOTChallenge sequence (gym.make(..., sequence=folder); "
          "any command takes its folder)")
    return 0


def cmd_trackers(args) -> int:
    from mtt_sim import trackers

    for name, cls in sorted(trackers.base.REGISTRY.items()):
        print(f"{name}: {cls.description}")
        for line in trackers.base.describe(name):
            print("    " + line)
    return 0


def cmd_perf(args) -> int:
    from tqdm import tqdm

    from mtt_sim.lab import perf

    sections = [("env", lambda: perf.report(perf.measure(repeats=args.repeats, steps=args.steps))),
                ("scenarios", lambda: perf.report_scenarios(perf.measure_scenarios(repeats=args.repeats, steps=args.steps))),
                ("scaling", lambda: perf.report_scaling(perf.measure_scaling(repeats=args.repeats))),
                ("metrics", lambda: perf.report_metrics(perf.measure_metrics(repeats=args.repeats))),
                ("metrics memory", lambda: perf.report_metrics_memory(perf.measure_metrics_memory(repeats=args.repeats))),
                ("jpda", lambda: perf.report_jpda(perf.measure_jpda(repeats=args.repeats))),
                ("lmb", lambda: perf.report_lmb(perf.measure_lmb(repeats=args.repeats))),
                ("rfs", lambda: perf.report_rfs(perf.measure_rfs(repeats=args.repeats))),
                ("particle filters", lambda: perf.report_pf(perf.measure_pf(repeats=args.repeats))),
                ("sweeps", lambda: perf.report_sweeps(perf.measure_sweeps(repeats=args.repeats)))]
    with tqdm(sections, unit="section", leave=False) as bar:
        for name, measure in bar:
            bar.set_description(f"measuring {name}")
            bar.write(measure() + "\n")
    return 0


def cmd_learn_reid(args) -> int:
    from mtt_sim.trackers import reid

    out = reid.METRIC_FILE if args.install else Path(args.out)
    _output(str(out), args.force or args.install, "--out", (".npz",))
    from mtt_sim.lab import learn_reid

    summary = learn_reid.learn(out, args.scenario, args.seeds, args.frames, args.every, args.dims, progress=True)
    for k, v in summary.items():
        print(f"{k:12s} {v}")
    if not args.install:
        print(f"use it with --tracker 'lmb:reid_metric={out}' (or relearn with --install to replace the shipped one)")
    return 0


def cmd_export(args) -> int:
    overrides = _overrides(args)
    _loaded([args.scenario], overrides)
    out = Path(args.out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())) and not args.force:
        raise UsageError("--out", f"{args.out!r} exists and is not empty; add --force to replace its sequence")
    _writable_folder(out if out.is_dir() else out.parent, "--out", args.out)
    from mtt_sim.real import motchallenge

    summary = motchallenge.export(args.scenario, out, args.seed, args.steps, overrides, progress=True)
    for k, v in summary.items():
        print(f"{k:12s} {v}")
    return 0


def cmd_docs(args) -> int:
    out = Path(args.out)
    if out.exists() and (not out.is_dir() or any(out.iterdir())) and not args.force:
        raise UsageError("--out", f"{args.out!r} exists and is not empty; add --force to replace the site")
    _writable_folder(out if out.is_dir() else out.parent, "--out", args.out)
    _require("mkdocs", "docs", "docs")
    _require("material", "docs", "docs")
    import tempfile

    from mtt_sim.show import docsite

    with tempfile.TemporaryDirectory() as work:
        docsite.build(out, Path(work))
    print(f"site: {out / 'index.html'}")
    return 0


def cmd_eval(args) -> int:
    for argument, path, kind in (("--gt", Path(args.gt) / "gt" / "gt.txt", "a sequence folder with gt/gt.txt"),
                                 ("--results", Path(args.results), "a results file")):
        if not path.is_file():
            raise UsageError(argument, f"{str(path)!r} not found; expected {kind}")
    from mtt_sim.real import motchallenge

    s = scenario.ScoringConfig()
    metrics = motchallenge.evaluate_results(args.gt, args.results, benchmark=args.benchmark, similarity=args.similarity,
                                            threshold=args.threshold, zero_distance=s.zero_distance,
                                            gospa_c=s.gospa_c, gospa_p=s.gospa_p)
    summary = {k: metrics[k] for k in SUMMARY_KEYS}
    if args.json:
        print(json.dumps(summary))
        return 0
    _print_summary(summary)
    return 0


def _print_summary(summary: dict) -> None:
    """One metric a line: floats to 3 decimals, "-" for a measure with no value (no occlusion decided, say)."""
    for k, v in summary.items():
        print(f"{k:17s} {v:.3f}" if isinstance(v, float) else f"{k:17s} {'-' if v is None else v}")


def cmd_check_real(args) -> int:
    if not (Path(args.data) / "mot15").is_dir():
        raise UsageError("data", f"{args.data!r}: expected the shared data folder (with mot15/, reference/, mot17/)")
    from mtt_sim.real import check as check_real

    return 0 if check_real.check(args.data) else 1


def cmd_calibrate(args) -> int:
    out = _output(args.out, args.force, "--out", (".toml",))
    from mtt_sim.real import calibrate

    fitted = calibrate.calibrate(args.folders, seeds=args.seeds)
    print(calibrate.report(fitted))
    out.write_text(calibrate.to_toml(fitted))
    print(f"\nsensor: {out}" + (" (replaced)" if args.force else "")
          + f"; replay a sequence through it: mtt-sim run DIR --detector synthetic --sensor {shlex.quote(str(out))}")
    return 0


def cmd_validate(args) -> int:
    out = _output(args.out, args.force, "--out", (".md",))
    from mtt_sim.real import validate

    result = validate.validate(args.folders, args.trackers or validate.TRACKERS, seeds=args.seeds, workers=args.workers, progress=True)
    text = validate.markdown(result)
    print(text)
    if out:
        out.write_text(text)
        print(f"tables: {out}" + (" (replaced)" if args.force else ""))
    return 1 if result.failed else 0


def cmd_config(args) -> int:
    overrides = _overrides(args)
    if args.scenario:
        _loaded([args.scenario], overrides)
        print(json.dumps(scenario.to_mapping(scenario.load(args.scenario, overrides)), indent=2))
    else:
        print(scenario.reference_table())
    return 0


# ------------------------------------------------------------------ the parser

def _add_overrides(parser: argparse.ArgumentParser, config_help: str) -> None:
    """--config, and the detector's two shortcuts: --detector (sensor.model) and --sensor (a [sensor] table file)."""
    parser.add_argument("--config", nargs="*", default=[], metavar="KEY=VALUE", help=config_help)
    parser.add_argument("--detector", choices=("synthetic", "foreground", "recorded"),
                        help="sensor.model: on a sequence folder, 'synthetic' replays its ground truth through the "
                             "synthetic detector (its twin) instead of det/det.txt ('recorded', the default there)")
    parser.add_argument("--sensor", metavar="FILE.toml",
                        help="the [sensor] table of this file (e.g. from mtt-sim calibrate) as overrides; --config wins")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="mtt-sim", description="A Gymnasium environment for video multi-target tracking.")
    p.add_argument("--version", action="version", version=f"mtt-sim {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)
    sub.add_parser("list", help="scenarios with their env ids and one-line descriptions").set_defaults(func=cmd_list)
    sub.add_parser("trackers", help="trackers with their descriptions and parameters (default, allowed values)"
                   ).set_defaults(func=cmd_trackers)
    scenario_help = ("scenario key (see `mtt-sim list`, any case), env id (mtt_sim/Crossing-v0), .toml file or a "
                     "MOTChallenge sequence folder")
    config_help = "overrides, e.g. sensor.clutter_rate=5 groups.0.count=10"
    force_help = "replace an existing output"

    run = sub.add_parser("run", help="run one episode with a tracker and print its metrics")
    run.add_argument("scenario", type=_scenario, help=scenario_help)
    run.add_argument("--tracker", type=_tracker_spec, default="sort",
                     help="tracker spec, e.g. sort or 'sort:max_age=3,min_hits=1' (default: sort)")
    run.add_argument("--seed", type=_integer(0), default=0, help="episode seed, >= 0 (default 0)")
    run.add_argument("--steps", type=_integer(1), default=None, help="at most this many steps (default: the "
                                                                        "scenario's env.max_steps)")
    run.add_argument("--video", help="write an annotated video: .mp4 (H.264) or .gif")
    run.add_argument("--compare", type=_tracker_specs,
                     help="several trackers on the same episode, one video panel each, side by side (comma-separated "
                          "specs, or ';'-separated: 'sort;jpda:coast=false')")
    run.add_argument("--scale", type=_integer(1, 8), default=1, help="enlarge the video's frames this many "
                                                                     "times (1 to 8; for small scenes)")
    run.add_argument("--results", help="write the tracks as a MOTChallenge results file (.txt; an offline method's "
                                       "offline output)")
    run.add_argument("--force", action="store_true", help=force_help)
    _add_overrides(run, config_help)
    run.add_argument("--json", action="store_true", help="print the summary as JSON")
    run.set_defaults(func=cmd_run)

    for name, func, text in (("bench", cmd_bench, "a tracker x scenario x seed grid, as a table of mean and 95%% "
                                                   "interval"),
                             ("sweep", cmd_sweep, "a stress curve: one scenario, one parameter over several values")):
        g = sub.add_parser(name, help=text)
        if name == "bench":
            g.add_argument("--scenarios", type=_scenarios, required=True, help="comma-separated scenarios")
            g.add_argument("--by", choices=("scenario", "target"), default="scenario",
                           help="columns: scenarios, or ground-truth ids for the per-target metrics (CentreError, "
                                "Coverage, HiddenCentreError, Reacquired; hand-initialised trackers; one scenario)")
        else:
            g.add_argument("scenario", type=_scenario, help=scenario_help)
            g.add_argument("--param", required=True, metavar="KEY=V1,V2,...", help="e.g. sensor.clutter_rate=0,2,5,10,20")
        g.add_argument("--plot", help="write a plot, one panel per --metric (bench: bars per scenario; sweep: curves), "
                                      "as a PNG, PDF or SVG (needs the [plot] extra: matplotlib)")
        g.add_argument("--trackers", type=_tracker_specs, required=True,
                       help="tracker specs separated by commas, or by ';' when a spec has several parameters: "
                            "sort,iou,gnn:coast=true or 'sort:min_hits=1,max_age=5;iou'")
        g.add_argument("--seeds", type=parse_seeds, default=parse_seeds("5"),
                       help="a count (5: seeds 0..4, the default), a list (3,7,11) or a range (100-199)")
        g.add_argument("--workers", type=_integer(1), default=1,
                       help="parallel processes, or a local Ray instance's CPUs (default 1)")
        g.add_argument("--backend", choices=("local", "ray"), default="local",
                       help="local processes, or Ray tasks (the [ray] extra)")
        g.add_argument("--address", help="with --backend ray: a Ray cluster's address (default: start a local one)")
        g.add_argument("--metric", type=_metrics, default=["MOTA"],
                       help="metric(s) of the tables, comma-separated, any case (default MOTA)")
        g.add_argument("--out", help="write every episode's record as it finishes (.csv or .json)")
        g.add_argument("--results-dir", help="write every episode's tracks as a MOTChallenge results file in this folder")
        g.add_argument("--force", action="store_true", help=force_help)
        _add_overrides(g, "overrides for every episode")
        g.set_defaults(func=func)

    pf = sub.add_parser("perf", help="speed and memory of the env, the metrics and the trackers, each against a "
                                     "same-run reference")
    pf.add_argument("--repeats", type=_integer(1), default=5, help="medians over this many repeats (default 5)")
    pf.add_argument("--steps", type=_integer(1), default=200, help="env steps per repeat (default 200)")
    pf.set_defaults(func=cmd_perf)

    lr = sub.add_parser("learn-reid", help="learn lmb's XQDA re-identification metric from rendered crops")
    lr.add_argument("--scenario", type=_scenario, default="mot17_like", help=scenario_help)
    lr.add_argument("--seeds", type=parse_seeds, default=parse_seeds("1000-1003"),
                    help="training episodes: a count, list or range (default 1000-1003, away from the experiments' 0..9)")
    lr.add_argument("--frames", type=_integer(1), default=300, help="frames per episode (default 300)")
    lr.add_argument("--every", type=_integer(1), default=15, help="take crops every this many frames (default 15)")
    lr.add_argument("--dims", type=_integer(1, 200), default=16, help="XQDA subspace dimension (default 16)")
    lr.add_argument("--out", default="xqda.npz", help="where to write the metric (default: xqda.npz here)")
    lr.add_argument("--install", action="store_true", help="replace the metric the package ships (every lmb uses it)")
    lr.add_argument("--force", action="store_true", help=force_help)
    lr.set_defaults(func=cmd_learn_reid)

    ex = sub.add_parser("export", help="write an episode as a MOTChallenge sequence (frames, gt, detections)")
    ex.add_argument("scenario", type=_scenario, help=scenario_help)
    ex.add_argument("--out", required=True, help="the sequence folder to write")
    ex.add_argument("--seed", type=_integer(0), default=0, help="episode seed, >= 0 (default 0)")
    ex.add_argument("--steps", type=_integer(1), default=None, help="at most this many frames (default: env.max_steps)")
    ex.add_argument("--force", action="store_true", help="write into a folder that is not empty (its old frames go)")
    _add_overrides(ex, config_help)
    ex.set_defaults(func=cmd_export)

    ev = sub.add_parser("eval", help="score a MOTChallenge results file against a sequence's ground truth, as TrackEval")
    ev.add_argument("--gt", required=True, help="the sequence folder (gt/gt.txt; seqinfo.ini if it has one)")
    ev.add_argument("--benchmark", choices=("MOT15", "MOT16", "MOT17", "MOT20"),
                    help="the scoring rules (default: from the folder's name, else MOT17 where gt.txt has classes, "
                         "else MOT15)")
    ev.add_argument("--results", required=True, help="frame, id, x, y, w, h, ... per line")
    ev.add_argument("--similarity", choices=("iou", "centroid"), default="iou")
    ev.add_argument("--threshold", type=_fraction, default=0.5, help="match threshold in (0, 1] (default 0.5)")
    ev.add_argument("--json", action="store_true")
    ev.set_defaults(func=cmd_eval)

    cr = sub.add_parser("check-real", help="hold sort, bytetrack and the scoring against real MOTChallenge data and "
                                           "the reference codes' outputs")
    cr.add_argument("data", help="the shared data folder (mot15/, reference/, mot17/, mot17_results/)")
    cr.set_defaults(func=cmd_check_real)

    ca = sub.add_parser("calibrate", help="fit the synthetic detector to real detections: print the fit beside the "
                                          "data and write a [sensor] table")
    ca.add_argument("folders", nargs="+", type=_calibration_folder, metavar="DIR",
                    help="sequence folders with gt/gt.txt and det/det.txt (fitted together)")
    ca.add_argument("--out", required=True, help="the [sensor] table to write (.toml)")
    ca.add_argument("--seeds", type=_integer(1), default=3, help="twin runs averaged in the check (default 3)")
    ca.add_argument("--force", action="store_true", help=force_help)
    ca.set_defaults(func=cmd_calibrate)

    va = sub.add_parser("validate", help="the sim-to-real check: trackers on real detections against the twins "
                                         "(fitted here, on the other sequences, memoryless)")
    va.add_argument("folders", nargs="+", type=_calibration_folder, metavar="DIR",
                    help="sequence folders with gt/gt.txt and det/det.txt (two or more for leave-one-out)")
    va.add_argument("--trackers", type=_tracker_specs, default=None,
                    help="tracker specs (default: sort,iou,bytetrack,gnn,gmphd,lmb:reid=false,jpda)")
    va.add_argument("--seeds", type=_integer(1), default=3, help="twin episodes per sequence and tracker (default 3)")
    va.add_argument("--workers", type=_integer(1), default=1, help="parallel processes (default 1)")
    va.add_argument("--out", help="also write the tables to this Markdown file (.md)")
    va.add_argument("--force", action="store_true", help=force_help)
    va.set_defaults(func=cmd_validate)

    dc = sub.add_parser("docs", help="build the documentation site (MkDocs): the README, a page per scenario and "
                                     "per tracker, the configuration reference (the [docs] extra)")
    dc.add_argument("--out", required=True, help="the site's folder")
    dc.add_argument("--force", action="store_true", help=force_help)
    dc.set_defaults(func=cmd_docs)

    cf = sub.add_parser("config", help="the configuration reference, or one scenario's resolved configuration")
    cf.add_argument("scenario", nargs="?", type=_scenario, help=scenario_help)
    _add_overrides(cf, config_help)
    cf.set_defaults(func=cmd_config)
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

