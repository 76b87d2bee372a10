"""Experiments: one episode, tracker x scenario x seed grids in parallel processes, sweeps, tables.

A record is a plain dict: tracker (the spec as given, e.g. "sort:max_age=3"), params (the tracker's
resolved parameters), scenario, seed, config (the overrides), metrics (the episode summary),
tracker_fps (frames per second of tracker time alone) and env_fps (of env time alone).
The same arguments give the same records, whatever the number of workers.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import multiprocessing
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Mapping, Sequence

import numpy as np
from scipy import stats

import trackers

from .env import TrackingEnv
from .overlay import VideoWriter, draw_debug


def run_episode(scenario: str, tracker: str = "sort", seed: int = 0, config: Mapping | None = None,
                video: str | None = None, steps: int | None = None) -> dict:
    """One episode of `tracker` on `scenario`; optionally an annotated video. Returns a record."""
    agent = trackers.make(tracker)
    obs_mode = "frame+detections" if agent.needs_frame or video else "detections"
    env = TrackingEnv(scenario, config=config, render_mode="rgb_array" if video else None, obs_mode=obs_mode)
    obs, info = env.reset(seed=seed)
    agent.reset(info)
    writer = VideoWriter(video, (env.scenario.render.width, env.scenario.render.height)) if video else None
    tracker_time = env_time = 0.0
    limit = steps or env.scenario.env.max_steps
    for _ in range(limit):
        start = time.perf_counter()
        tracks = agent.update(obs)
        mid = time.perf_counter()
        action = tracks.to_action(env.action_space)
        if writer:
            env.remember_tracks(tracks.ids, tracks.boxes)
            writer.write(draw_debug(env.render(), agent.debug()))
        obs, _, terminated, truncated, info = env.step(action)
        tracker_time, env_time = tracker_time + mid - start, env_time + time.perf_counter() - mid
        if terminated or truncated:
            break
    if writer:
        writer.close()
    metrics = env.metrics.summary()
    frames = metrics["num_frames"]
    return {"tracker": tracker, "params": agent.params, "scenario": str(scenario), "seed": seed,
            "config": dict(config or {}), "metrics": metrics, "per_target": env.metrics.per_target(),
            "tracker_fps": frames / max(tracker_time, 1e-9), "env_fps": frames / max(env_time, 1e-9)}


def _task(args):
    return run_episode(*args)


BACKENDS = ("local", "ray")


def run_grid(tracker_specs: Sequence[str], scenarios: Sequence[str], seeds: Sequence[int] | int,
             config: Mapping | None = None, configs: Sequence[Mapping] | None = None, workers: int = 1,
             progress: bool = False, backend: str = "local", address: str | None = None) -> list[dict]:
    """Every tracker x scenario x seed (x config, for sweeps); records in grid order. backend="local" runs them in
    `workers` processes; "ray" as Ray tasks, on a local Ray instance of `workers` CPUs or on the cluster at
    `address` (the [ray] extra)."""
    if backend not in BACKENDS:
        raise ValueError(f"backend={backend!r}: allowed values: {', '.join(map(repr, BACKENDS))}")
    seeds = range(seeds) if isinstance(seeds, int) else seeds
    for spec in tracker_specs:
        trackers.make(spec)  # fail fast on a bad spec, before any process starts
    tasks = [(sc, spec, seed, {**(config or {}), **c}) for c, sc, spec, seed in
             itertools.product(configs or [{}], scenarios, tracker_specs, seeds)]
    bar = _Progress(len(tasks)) if progress else None
    if backend == "ray":
        return _run_on_ray(tasks, workers, address, bar)
    if workers <= 1:
        records = []
        for t in tasks:
            records.append(_task(t))
            bar and bar.step(t)
        return records
    records = [None] * len(tasks)
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        futures = {pool.submit(_task, t): i for i, t in enumerate(tasks)}
        for done in as_completed(futures):
            records[futures[done]] = done.result()
            bar and bar.step(tasks[futures[done]])
    return records


def _run_on_ray(tasks: list, workers: int, address: str | None, bar) -> list[dict]:
    """The episodes as Ray tasks, collected as they finish; a Ray instance started here is shut down after."""
    try:
        import ray
    except ImportError:
        raise ImportError("backend 'ray' needs Ray: pip install 'mtt-sim[ray]'") from None
    started = not ray.is_initialized()
    if started:
        ray.init(address=address, num_cpus=None if address else max(1, workers), include_dashboard=False,
                 log_to_driver=False, configure_logging=False)
    try:
        remote = ray.remote(_task)
        index = {remote.remote(t): i for i, t in enumerate(tasks)}
        records, pending = [None] * len(tasks), list(index)
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            i = index[done[0]]
            records[i] = ray.get(done[0])
            bar and bar.step(tasks[i])
        return records
    finally:
        if started:
            ray.shutdown()


class _Progress:
    """A one-line progress bar on stderr."""

    def __init__(self, total: int):
        self.total, self.done, self.start = total, 0, time.perf_counter()

    def step(self, task):
        self.done += 1
        filled = int(30 * self.done / self.total)
        elapsed = time.perf_counter() - self.start
        eta = elapsed / self.done * (self.total - self.done)
        sys.stderr.write(f"\r[{'#' * filled}{'.' * (30 - filled)}] {self.done}/{self.total} "
                         f"{task[1]} on {task[0]} seed {task[2]}  {elapsed:.0f}s, {eta:.0f}s left   ")
        if self.done == self.total:
            sys.stderr.write("\n")
        sys.stderr.flush()


def mean_ci(values: Sequence[float], level: float = 0.95) -> tuple[float, float]:
    """Mean and half-width of its Student-t confidence interval (0 for a single value)."""
    v = np.asarray(values, float)
    if len(v) < 2:
        return float(v.mean()) if len(v) else math.nan, 0.0
    half = stats.t.ppf(0.5 + level / 2, len(v) - 1) * v.std(ddof=1) / math.sqrt(len(v))
    return float(v.mean()), float(half)


def summarize(records: Sequence[dict], metric: str = "MOTA", by: str = "scenario") -> list[dict]:
    """One row per (tracker, `by`) cell: the metric's mean and 95 % interval over seeds, and the speeds. `by` is
    "scenario", "config" (sweeps) or "target" (a per-target metric, CentreError or Coverage, per GT id)."""
    cells: dict[tuple, list[tuple[float, dict]]] = {}
    for r in records:
        if by == "target":
            per = r["per_target"]
            if per and metric not in next(iter(per.values())):
                raise ValueError(f"unknown per-target metric {metric!r}; available: {', '.join(next(iter(per.values())))}")
            for gid, values in sorted(per.items(), key=lambda kv: int(kv[0])):
                cells.setdefault((r["tracker"], f"target {gid}"), []).append((values[metric], r))
            continue
        if metric not in r["metrics"]:
            raise ValueError(f"unknown metric {metric!r}; available: {', '.join(r['metrics'])}")
        column = r["scenario"] if by == "scenario" else json.dumps(r["config"], sort_keys=True)
        cells.setdefault((r["tracker"], column), []).append((r["metrics"][metric], r))
    rows = []
    for (tracker, column), cell in cells.items():
        values = np.array([v for v, _ in cell], float)
        mean, ci = mean_ci(values[np.isfinite(values)])
        rs = [r for _, r in cell]
        rows.append({"tracker": tracker, "column": column, "metric": metric, "mean": mean, "ci95": ci, "n": len(rs),
                     "tracker_fps": float(np.median([r["tracker_fps"] for r in rs])),
                     "env_fps": float(np.median([r["env_fps"] for r in rs]))})
    return rows


def markdown(rows: Sequence[dict], title: str = "") -> str:
    """Trackers x columns table of mean ± 95 % interval, with median frames/s of tracker time and of env time."""
    trackers_, columns = list(dict.fromkeys(r["tracker"] for r in rows)), list(dict.fromkeys(r["column"] for r in rows))
    cell = {(r["tracker"], r["column"]): r for r in rows}
    metric, n = rows[0]["metric"], rows[0]["n"]
    head = f"{metric} (mean ± 95% interval over {n} seeds)" + (f", {title}" if title else "")
    lines = [head, "", "| tracker | " + " | ".join(columns) + " | tracker frames/s | env frames/s |",
             "|---|" + "---:|" * (len(columns) + 2)]
    for t in trackers_:
        values = [f"{cell[t, c]['mean']:.3f} ± {cell[t, c]['ci95']:.3f}" if (t, c) in cell else "" for c in columns]
        fps, env_fps = (np.median([cell[t, c][k] for c in columns if (t, c) in cell]) for k in ("tracker_fps", "env_fps"))
        lines.append(f"| {t} | " + " | ".join(values) + f" | {fps:.0f} | {env_fps:.0f} |")
    return "\n".join(lines)


def write_records(records: Sequence[dict], path: str | Path) -> None:
    """Records as JSON (.json) or CSV (anything else: one row per episode, metrics as columns)."""
    path = Path(path)
    if path.suffix == ".json":
        path.write_text(json.dumps(list(records), indent=1))
        return
    metric_keys = list(records[0]["metrics"]) if records else []
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["tracker", "params", "scenario", "seed", "config", "tracker_fps", "env_fps", *metric_keys])
        for r in records:
            w.writerow([r["tracker"], json.dumps(r["params"], sort_keys=True), r["scenario"], r["seed"],
                        json.dumps(r["config"], sort_keys=True), f"{r['tracker_fps']:.1f}", f"{r['env_fps']:.1f}",
                        *(r["metrics"][k] for k in metric_keys)])


def sweep_plot(rows: Sequence[dict], param: str, values: Sequence, path: str | Path) -> None:
    """A stress curve (metric against the swept value, one line per tracker) as a PNG; needs matplotlib."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError("the sweep plot needs matplotlib: pip install 'mtt-sim[plot]'") from None
    fig, ax = plt.subplots(figsize=(6, 4))
    for t in dict.fromkeys(r["tracker"] for r in rows):
        mine = [r for r in rows if r["tracker"] == t]
        mean, ci = np.array([r["mean"] for r in mine]), np.array([r["ci95"] for r in mine])
        ax.errorbar(values, mean, yerr=ci, marker="o", capsize=3, label=t)
    ax.set_xlabel(param)
    ax.set_ylabel(rows[0]["metric"])
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
