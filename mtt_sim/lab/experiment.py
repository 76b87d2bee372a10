"""Experiments: one episode, tracker x scenario x seed grids in parallel processes, sweeps, tables.

A record is a plain dict: tracker (the spec as given, e.g. "sort:max_age=3"), params (the tracker's
resolved parameters), scenario, seed, config (the overrides), error (None, or the one-line message of
what failed), metrics (the episode summary; None if it failed), per_target, tracker_fps (frames per
second of tracker time alone) and env_fps (of env time alone). The same arguments give the same records,
whatever the number of workers. A failing episode is recorded as failed and the rest of the grid goes on.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import os
import re
from pathlib import Path
from typing import Callable, Iterator, Mapping, Sequence

import cv2
import numpy as np
from scipy.special import stdtrit
from tqdm import tqdm

from mtt_sim import trackers

from mtt_sim.lab import pool
from mtt_sim.lab.episode import Episode
from mtt_sim.lab.journal import Journal
from mtt_sim.env import TrackingEnv
from mtt_sim.metrics import METRICS, PER_TARGET
from mtt_sim.real.motchallenge import write_results
from mtt_sim.sources import SourceSpec
from mtt_sim.show.video import VideoWriter

BACKENDS = ("local", "ray")


def _episode(scenario: str, spec: str, seed: int, config: Mapping | None, steps: int | None, render: bool,
             scale: int) -> Episode:
    """Tracker `spec` on its own env of `scenario`, reset with `seed` (frames in its observations if it reads them)."""
    agent = trackers.TrackerSpec.of(spec).make()
    env = TrackingEnv(scenario, config=config, render_mode="rgb_array" if render else None,
                      obs_mode="frame+detections" if agent.needs_frame else "detections", render_scale=scale)
    return Episode(env, seed, agent, steps)


def _record(run: Episode, spec: str, online: list, scenario: str, seed: int, config: Mapping | None) -> dict:
    """The record of tracker `spec`'s finished episode, which reported the tracks `online`."""
    env, frames = run.env, len(online)
    scored = env.scored
    return {"tracker": str(spec), "params": run.agent.params, "scenario": str(scenario), "seed": seed,
            "config": dict(config or {}), "error": None, "metrics": env.metrics.summary() if scored else None,
            "per_target": env.metrics.per_target() if scored else {},
            "tracker_fps": frames / max(run.tracker_time, 1e-9), "env_fps": frames / max(run.env_time, 1e-9)}


def run_episodes(scenario: str, specs: Sequence[str], seed: int = 0, config: Mapping | None = None,
                 video: str | None = None, steps: int | None = None, progress: bool = False, scale: int = 1,
                 results: str | None = None, still: str | None = None) -> list[dict]:
    """One episode of each tracker in `specs` on `scenario` (a shipped key, a .toml file or a recorded sequence's
    folder), all on the same seed and so the same world, stepped together; optionally an annotated video with one
    panel per tracker side by side (each with its own banner, frames enlarged `scale` times), a progress bar (shown
    once the episode has run for a second) and, for a single tracker, a MOTChallenge results file of its tracks
    (`tracker.results`: the offline output of an offline method), and a still (an image file) of the frame where the
    tracker's step reward was lowest (of several trackers: where their rewards differ most). Returns a record per
    tracker; its metrics are None on a recorded sequence without ground truth."""
    if results and len(specs) != 1:
        raise ValueError("a results file takes one tracker")
    drawn = bool(video or still)
    runs = [_episode(scenario, spec, seed, config, steps, drawn, scale) for spec in specs]
    worst: tuple[float, np.ndarray] | None = None  # the still's frame, and how bad or how split it was
    online: list[list[trackers.Tracks]] = [[] for _ in runs]
    writer = VideoWriter(video, runs[0].env.metadata["render_fps"]) if video else None
    with tqdm(total=runs[0].limit, desc=f"{','.join(specs)} on {scenario}", unit="frame", delay=1.0, leave=False,
              disable=not progress) as bar:
        while not runs[0].done:  # the same world: every run ends on the same frame
            panels = []
            for run, spec, tracks in zip(runs, specs, online):
                run.answer()
                n = run.action["num_tracks"]
                tracks.append(trackers.Tracks.of(run.action["ids"][:n], run.action["boxes"][:n]))
                if drawn:
                    run.env.remember_tracks(run.tracks.ids, run.tracks.boxes, run.agent.debug(), spec)
                    panels.append(run.env.render())
                run.advance()
            if drawn:  # panels side by side, a dark gap between them
                gap = np.full((panels[0].shape[0], 4, 3), 30, np.uint8)
                picture = np.concatenate([x for panel in panels for x in (gap, panel)][1:], axis=1)
                if writer:
                    writer.write(picture)
                if still:
                    rewards = [run.reward for run in runs]
                    badness = max(rewards) - min(rewards) if len(runs) > 1 else -rewards[0]
                    if worst is None or badness > worst[0]:
                        worst = (badness, picture)
            bar.update()
    if writer:
        writer.close()
    if worst is not None:
        cv2.imwrite(still, cv2.cvtColor(worst[1], cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 80])
    if results:
        write_results(results, [(t.ids, t.boxes) for t in runs[0].agent.results(online[0])])
    return [_record(run, spec, tracks, scenario, seed, config) for run, spec, tracks in zip(runs, specs, online)]


def run_episode(scenario: str, tracker: str = "sort", seed: int = 0, config: Mapping | None = None,
                results: str | None = None, video: str | None = None, steps: int | None = None,
                progress: bool = False) -> dict:
    """One episode of `tracker` on `scenario`: `run_episodes` with one tracker."""
    return run_episodes(scenario, [tracker], seed, config, video, steps, progress, results=results)[0]


def score(record: dict, metric: str) -> float:
    """An episode record's `metric`; an unscored one is an error, not a zero."""
    value = (record["metrics"] or {}).get(metric)
    if value is None:
        raise RuntimeError(f"{record['scenario']}: no {metric} (an unscored source, or nothing to count)")
    return float(value)


def failed_record(task: tuple, message: str) -> dict:
    """The record of grid task (scenario, tracker, seed, config, results file) whose episode failed with `message`."""
    scenario, tracker, seed, config, _ = task
    return {"tracker": tracker, "params": {}, "scenario": str(scenario), "seed": seed, "config": dict(config),
            "error": message, "metrics": None, "per_target": {}, "tracker_fps": math.nan, "env_fps": math.nan}


class _Episodes:
    """Grid episodes run in one process. A task names its source and tracker spec by strings (what crosses between
    processes and keys a journal); each is parsed once a process, or taken as the caller already parsed it."""

    def __init__(self, parsed: Sequence = ()):
        self.sources = {str(p): p for p in parsed if isinstance(p, SourceSpec)}
        self.specs = {str(p): p for p in parsed if isinstance(p, trackers.TrackerSpec)}

    def __call__(self, task: tuple) -> dict:
        """One grid episode; an exception in it becomes a failed record with the error's first line."""
        scenario, spec, *rest = task
        try:
            if isinstance(scenario, (str, os.PathLike)):
                scenario = _once(self.sources, str(scenario), SourceSpec)
            return run_episode(scenario, _once(self.specs, spec, trackers.TrackerSpec), *rest)
        except Exception as err:  # noqa: BLE001  (whatever one episode raises, the grid goes on)
            return failed_record(task, f"{type(err).__name__}: {(str(err).splitlines() or [''])[0]}")


def _once(parsed: dict, text: str, kind: type):
    """`text` parsed as `kind`, the first time it is asked for."""
    if text not in parsed:
        parsed[text] = kind(text)
    return parsed[text]


_WORKER = _Episodes()  # a worker process's own: what its tasks name, parsed once


def _task(task: tuple) -> dict:
    """One grid episode in a worker process (local or Ray)."""
    return _WORKER(task)


def run_grid(tracker_specs: Sequence[str], scenarios: Sequence[str], seeds: Sequence[int] | int,
             config: Mapping | None = None, configs: Sequence[Mapping] | None = None, workers: int = 1,
             progress: bool = False, backend: str = "local", address: str | None = None,
             on_record: Callable[[dict], None] | None = None, results_dir: str | Path | None = None,
             journal: Journal | None = None) -> list[dict]:
    """Every tracker x scenario x seed (x config, for sweeps); records in grid order. backend="local" runs them in
    `workers` processes; "ray" as Ray tasks, on a local Ray instance of `workers` CPUs or on the cluster at
    `address` (the [ray] extra). `on_record` is called with each record as it finishes, so an interrupted grid
    keeps what it finished (KeyboardInterrupt stops the workers and propagates); a `journal` keeps them too, and
    the episodes it holds are not run again. With `results_dir`, every episode writes its tracks as a MOTChallenge
    results file, `results_dir/<tracker>/<scenario>[-seed<k>][-<config>].txt`."""
    if backend not in BACKENDS:
        raise ValueError(f"backend={backend!r}: allowed values: {', '.join(map(repr, BACKENDS))}")
    seeds = range(seeds) if isinstance(seeds, int) else seeds
    specs = [trackers.TrackerSpec.of(spec) for spec in tracker_specs]  # a bad one fails before any process starts
    tasks = [(str(sc) if isinstance(sc, SourceSpec) else sc, str(spec), seed, {**(config or {}), **c},
              results_path(results_dir, spec, sc, seed if len(seeds) > 1 else None, c) if results_dir else None)
             for c, sc, spec, seed in itertools.product(configs or [{}], scenarios, specs, seeds)]
    return run_tasks(tasks, workers, progress, backend, address, on_record, journal=journal,
                     parsed=[*specs, *scenarios])


def run_tasks(tasks: Sequence[tuple], workers: int = 1, progress: bool = False, backend: str = "local",
              address: str | None = None, on_record: Callable[[dict], None] | None = None,
              processes: pool.Pool | None = None, journal: Journal | None = None,
              parsed: Sequence = ()) -> list[dict]:
    """Episodes (scenario, tracker, seed, config, results file or None) as `run_grid` runs them; records in order.
    `processes` (from `episode_pool`) runs them in workers already started, instead of `workers` new ones. Each
    finished record goes into `journal`, keyed by its task, and the tasks it already holds are taken from it.
    `parsed`: the `SourceSpec`s and `TrackerSpec`s the tasks name, as the caller parsed them (for episodes run here)."""
    records: list = [None] * len(tasks)
    keys = [repr(task) for task in tasks]
    kept = [i for i, key in enumerate(keys) if journal is not None and key in journal]
    missing = [i for i, key in enumerate(keys) if journal is None or key not in journal]
    with tqdm(total=len(tasks), initial=len(kept), unit="episode", disable=not progress, dynamic_ncols=True) as bar:
        for i in kept:
            records[i] = journal.get(keys[i])
            if on_record:
                on_record(records[i])
        for j, record in _finished([tasks[i] for i in missing], workers, backend, address, processes,
                                   _Episodes(parsed)):
            i = missing[j]
            records[i] = record
            if journal is not None:
                journal.put(keys[i], record)
            if on_record:
                on_record(record)
            bar.set_postfix_str(f"{record['tracker']} on {record['scenario']} seed {record['seed']}"
                                + (" failed" if record["error"] else ""), refresh=False)
            bar.update()
    return records


def results_path(folder: str | Path, tracker: str, scenario: str, seed: int | None, config: Mapping) -> Path:
    """Where a grid episode's results file goes: <folder>/<tracker>/<scenario name>[-seed<k>][-<key>=<value>...].txt
    (a recorded sequence's name is its folder's, as TrackEval expects)."""
    name = Path(scenario).stem if str(scenario).endswith(".toml") else Path(scenario).name
    parts = [name] + ([f"seed{seed}"] if seed is not None else []) + [f"{k}={v}" for k, v in config.items()]
    safe = lambda text: re.sub(r"[^A-Za-z0-9_.,=+-]", "_", str(text))  # noqa: E731
    path = Path(folder) / safe(tracker) / (safe("-".join(parts)) + ".txt")
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def episode_pool(workers: int) -> pool.Pool:
    """Worker processes that run grid episodes, kept for several `run_tasks` calls (a tuning study's trials)."""
    return pool.Pool(_task, workers)


def _finished(tasks: list, workers: int, backend: str, address: str | None, processes: pool.Pool | None,
              here: _Episodes) -> Iterator[tuple[int, dict]]:
    """(index, record) of every task as it finishes (run by `here` where they run in this process)."""
    if backend == "ray":
        yield from _on_ray(tasks, workers, address)
    elif processes is None and workers <= 1:
        for i, task in enumerate(tasks):
            yield i, here(task)
    else:
        done = processes.run(tasks) if processes is not None else pool.run(_task, tasks, workers)
        for i, value in done:
            yield i, failed_record(tasks[i], value.message) if isinstance(value, pool.TaskFailed) else value


def _on_ray(tasks: list, workers: int, address: str | None) -> Iterator[tuple[int, dict]]:
    """The episodes as Ray tasks, as they finish; a Ray instance started here is shut down after, and tasks still
    running when the caller stops are cancelled."""
    try:
        import ray
    except ImportError:
        raise ImportError("backend 'ray' needs Ray: pip install 'mtt-sim[ray]'") from None
    started = not ray.is_initialized()
    if started:
        ray.init(address=address, num_cpus=None if address else max(1, workers), include_dashboard=False,
                 log_to_driver=False, configure_logging=False)
    remote = ray.remote(_task)
    index = {remote.remote(t): i for i, t in enumerate(tasks)}
    pending = list(index)
    try:
        while pending:
            (ref,), pending = ray.wait(pending, num_returns=1)
            try:
                record = ray.get(ref)
            except ray.exceptions.RayError as err:  # the worker died (the episode's own errors are caught inside)
                record = failed_record(tasks[index[ref]], f"{type(err).__name__}: {(str(err).splitlines() or [''])[0]}")
            yield index[ref], record
    finally:
        for ref in pending:
            ray.cancel(ref, force=True)
        if started:
            ray.shutdown()


def mean_ci(values: Sequence[float], level: float = 0.95) -> tuple[float, float]:
    """Mean and half-width of its Student-t confidence interval (0 for a single value)."""
    v = np.asarray(values, float)
    if len(v) < 2:
        return float(v.mean()) if len(v) else math.nan, 0.0
    half = stdtrit(len(v) - 1, 0.5 + level / 2) * v.std(ddof=1) / math.sqrt(len(v))  # Student's t quantile
    return float(v.mean()), float(half)


def summarize(records: Sequence[dict], metric: str = "MOTA", by: str = "scenario") -> list[dict]:
    """One row per (tracker, `by`) cell: the metric's mean and 95 % interval over the seeds that ran, how many failed,
    and the speeds. `by` is "scenario", "config" (sweeps) or "target" (a per-target metric, one of PER_TARGET,
    per GT id)."""
    names = PER_TARGET if by == "target" else METRICS
    if metric not in names:
        raise ValueError(f"unknown {'per-target ' if by == 'target' else ''}metric {metric!r}; available: "
                         f"{', '.join(names)}")
    cells: dict[tuple, list[tuple[float, dict]]] = {}
    for r in records:
        column = _label(r["scenario"]) if by == "scenario" else json.dumps(r["config"], sort_keys=True)
        if r.get("metrics") is None and not r.get("error"):  # an unscored recorded sequence: nothing to average
            continue
        if r.get("error"):  # a failed cell; per target there is no column to put it in (the failures are listed apart)
            if by != "target":
                cells.setdefault((r["tracker"], column), []).append((math.nan, r))
        elif by == "target":
            for gid, values in sorted(r["per_target"].items(), key=lambda kv: int(kv[0])):
                cells.setdefault((r["tracker"], f"target {gid}"), []).append((values[metric], r))
        else:
            cells.setdefault((r["tracker"], column), []).append((r["metrics"][metric], r))
    rows = []
    for (tracker, column), cell in cells.items():
        ran = [(v, r) for v, r in cell if not r.get("error")]
        values = np.array([v for v, _ in ran], float)
        mean, ci = mean_ci(values[np.isfinite(values)])
        rows.append({"tracker": tracker, "column": column, "metric": metric, "mean": mean, "ci95": ci, "n": len(ran),
                     "valued": int(np.isfinite(values).sum()),  # episodes with a value (an occlusion window may have none)
                     "failed": len(cell) - len(ran), "integer": all(isinstance(v, int) for v, _ in ran),
                     "tracker_fps": float(np.median([r["tracker_fps"] for _, r in ran])) if ran else math.nan,
                     "env_fps": float(np.median([r["env_fps"] for _, r in ran])) if ran else math.nan})
    return rows


def _label(scenario: str) -> str:
    """A table's name for a scenario: its key, or the name of its .toml file or sequence folder."""
    path = Path(scenario)
    return path.stem if path.suffix == ".toml" else path.name


def markdown(rows: Sequence[dict], title: str = "") -> str:
    """Trackers x columns table of mean ± 95 % interval, with median frames/s of tracker time and of env time. A cell
    whose episodes all failed reads "failed"; one where some did says how many."""
    trackers_, columns = list(dict.fromkeys(r["tracker"] for r in rows)), list(dict.fromkeys(r["column"] for r in rows))
    cell = {(r["tracker"], r["column"]): r for r in rows}
    metric, n = rows[0]["metric"], max(r["n"] + r["failed"] for r in rows)
    head = (f"{metric} (mean ± 95% interval over {n} seeds)" if n > 1 else f"{metric} (one seed)") + \
        (f", {title}" if title else "")
    lines = [head, "", "| tracker | " + " | ".join(columns) + " | tracker frames/s | env frames/s |",
             "|---|" + "---:|" * (len(columns) + 2)]
    for t in trackers_:
        values = [_cell_text(cell.get((t, c))) for c in columns]
        speeds = ([cell[t, c][k] for c in columns if (t, c) in cell and cell[t, c]["n"]] for k in ("tracker_fps", "env_fps"))
        lines.append(f"| {t} | " + " | ".join(values) + " | " + " | ".join(
            f"{np.median(v):.0f}" if v else "-" for v in speeds) + " |")
    return "\n".join(lines)


def _cell_text(row: dict | None) -> str:
    if row is None:
        return ""
    if not row["n"]:
        return "failed"
    failed = f" ({row['failed']} of {row['n'] + row['failed']} failed)" if row["failed"] else ""
    if not row["valued"]:  # nothing to measure in any episode (no occlusion decided, say)
        return "-" + failed
    digits = 0 if row["integer"] and row["n"] == 1 else 1 if row["integer"] else 3
    value = f"{row['mean']:.{digits}f}" + (f" ± {row['ci95']:.{digits}f}" if row["valued"] > 1 else "")
    valued = f" ({row['valued']} of {row['n']} with a value)" if row["valued"] < row["n"] else ""
    return value + valued + failed


def write_records(records: Sequence[dict], path: str | Path) -> None:
    """Records as JSON (.json) or CSV (anything else: one row per episode, metrics as columns)."""
    with RecordFile(path) as out:
        for r in records:
            out.append(r)


class RecordFile:
    """Records written to a .json or CSV file as they come, the file complete and readable after every one."""

    HEADER = ["tracker", "params", "scenario", "seed", "config", "error", "tracker_fps", "env_fps", *METRICS]

    def __init__(self, path: str | Path):
        self.path, self.count = Path(path), 0
        self.json = self.path.suffix == ".json"
        self.file = self.path.open("wb" if self.json else "w", newline="" if not self.json else None)
        if self.json:
            self.file.write(b"[\n]\n")
        else:
            self.csv = csv.writer(self.file)
            self.csv.writerow(self.HEADER)
        self.file.flush()

    def append(self, r: dict) -> None:
        if self.json:  # overwrite the list's end, then end it again
            self.file.seek(-3 if self.count else -2, 2)
            self.file.write((b",\n" if self.count else b"") + json.dumps(r).encode() + b"\n]\n")
        else:
            self.csv.writerow([r["tracker"], json.dumps(r["params"], sort_keys=True), r["scenario"], r["seed"],
                               json.dumps(r["config"], sort_keys=True), r["error"] or "", f"{r['tracker_fps']:.1f}",
                               f"{r['env_fps']:.1f}", *((r["metrics"] or {}).get(k, "") for k in METRICS)])
        self.count += 1
        self.file.flush()

    def close(self) -> None:
        self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
