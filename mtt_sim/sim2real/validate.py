"""The sim-to-real check: `mtt-sim validate DIR [DIR ...]`.

Every detections-only tracker runs on each sequence's real detections and on its digital twin (the sequence's people
replayed through the synthetic detector, several seeds), with the detector fitted on the same sequence and, apart,
on the other sequences only (leave one out); and the same with the memoryless detector (`memory = false`: every frame
drawn independently at the fitted rates), so that what memory buys is measured in one run. The answer: per sequence
and tracker MOTA, IDF1 and IDSW, real against each twin; per detector the median absolute gaps and the mean Kendall
tau between the real and the twin rankings of the trackers; the twin's detector statistics against the data's.
With `scene`, each sequence's label-free fitted scene (`fit_scene` on its detections alone, the detector fitted on the
others) is judged the same way: what a camera without labels would predict of the trackers.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np
from scipy.stats import kendalltau

from mtt_sim.sim2real import calibrate

from mtt_sim.lab import experiment

TRACKERS = ("sort", "iou", "bytetrack", "gnn", "gmphd", "lmb:reid=false", "jpda")
METRICS = ("MOTA", "IDF1", "IDSW")
DETECTOR_STATISTICS = ("P(miss)", "P(miss | miss)", "mean miss run", "false positives per frame",
                       "mean false-positive run")
GOALS = {"MOTA": 3.0, "IDF1": 5.0, "tau": 0.7, "detector": 0.10}  # points, points, mean tau, relative gap


@dataclass(frozen=True)
class Twin:
    """One way of making a sequence's twin: which sequences the detector is fitted on, with memory or not, and
    whether the people are the sequence's own or its fitted scene's (label-free)."""

    name: str
    leave_one_out: bool
    memory: bool
    scene: bool = False


TWINS = (Twin("fitted here", False, True), Twin("fitted on the others", True, True),
         Twin("memoryless, fitted here", False, False), Twin("memoryless, on the others", True, False))
SCENE = Twin("fitted scene, on the others", True, True, scene=True)


@dataclass(frozen=True)
class Validation:
    """Real and twin metrics per (sequence, tracker), and detector statistics per sequence."""

    sequences: tuple[str, ...]
    trackers: tuple[str, ...]
    twins: tuple[Twin, ...]
    real: dict       # (sequence, tracker) -> {metric: value}
    twin: dict       # (twin name, sequence, tracker) -> {metric: mean over seeds}
    detector: dict   # (sequence, "data" or twin name) -> statistics
    seeds: int
    failed: tuple[str, ...]


def validate(folders: Sequence[str | Path], tracker_specs: Sequence[str] = TRACKERS, seeds: int = 3, workers: int = 1,
             progress: bool = False, scene: bool = False) -> Validation:
    """Run the check (see the module docstring). Leave-one-out twins and the fitted scene need two sequences or
    more."""
    sources = [calibrate.read(f) for f in folders]
    names = tuple(Path(f).name for f in folders)
    twins = tuple(t for t in TWINS + ((SCENE,) if scene else ()) if len(sources) > 1 or not t.leave_one_out)
    here = [calibrate.fitted([src]) for src in sources]
    others = [calibrate.fitted([o for j, o in enumerate(sources) if j != i])
              if len(sources) > 1 else None for i in range(len(sources))]
    sensors = {(t.name, i): {**(others[i] if t.leave_one_out else here[i]), "memory": t.memory}
               for t in twins for i in range(len(sources))}
    with tempfile.TemporaryDirectory() as work:
        scenes = {i: _fitted_scene(folder, sensors[t.name, i], Path(work)) for t in twins if t.scene
                  for i, folder in enumerate(folders)}
        tasks, keys = [], []
        for i, folder in enumerate(folders):
            for spec in tracker_specs:
                tasks.append((str(folder), spec, 0, {}, None))
                keys.append(("real", names[i], spec))
                for t in twins:
                    for seed in range(seeds):
                        tasks.append((scenes[i], spec, seed, {}, None) if t.scene else
                                     (str(folder), spec, seed, {"sensor": sensors[t.name, i]}, None))
                        keys.append((t.name, names[i], spec))
        records = experiment.run_tasks(tasks, workers, progress)
    real, twin, failed, values = {}, {}, [], {}
    for key, r in zip(keys, records):
        if r["error"]:
            failed.append(f"{r['tracker']} on {r['scenario']} seed {r['seed']}: {r['error']}")
            continue
        values.setdefault(key, []).append([r["metrics"][m] for m in METRICS])
    for key, rows in values.items():
        mean = dict(zip(METRICS, np.mean(rows, axis=0).tolist()))
        if key[0] == "real":
            real[key[1:]] = mean
        else:
            twin[key] = mean
    detector = {}
    for i, src in enumerate(sources):
        detector[names[i], "data"] = calibrate.statistics(src.associated)
        for t in twins:
            if not t.leave_one_out:
                detector[names[i], t.name] = calibrate.twin_statistics([src], sensors[t.name, i], seeds)
    return Validation(names, tuple(tracker_specs), twins, real, twin, detector, seeds, tuple(failed))


def _fitted_scene(folder, sensor: dict, work: Path) -> str:
    """The label-free scene of `folder` with the detector `sensor`, written in `work`; its path."""
    from mtt_sim.sim2real.fit_scene import fit_scene

    path = work / f"scene_{Path(folder).name}.toml"
    path.write_text(fit_scene(folder, sensor, seeds=())[3])
    return str(path)


# ------------------------------------------------------------------ what the check says

def gaps(v: Validation, twin: str, metric: str) -> np.ndarray:
    """Twin minus real over every (sequence, tracker) with both (MOTA and IDF1 in points)."""
    scale = 1.0 if metric == "IDSW" else 100.0
    return np.array([scale * (v.twin[twin, s, t][metric] - v.real[s, t][metric])
                     for s in v.sequences for t in v.trackers if (twin, s, t) in v.twin and (s, t) in v.real])


def taus(v: Validation, twin: str, metric: str = "MOTA") -> np.ndarray:
    """Per sequence, Kendall's tau between the real and the twin values of the metric over the trackers."""
    out = []
    for s in v.sequences:
        pairs = [(v.real[s, t][metric], v.twin[twin, s, t][metric]) for t in v.trackers
                 if (s, t) in v.real and (twin, s, t) in v.twin]
        if len(pairs) >= 2:
            out.append(kendalltau(*zip(*pairs)).statistic)
    return np.array(out, float)


def summary(v: Validation) -> list[dict]:
    """Per twin: median |gap| of MOTA, IDF1 (points) and IDSW, mean Kendall tau of MOTA and IDF1."""
    rows = []
    for t in v.twins:
        row = {"twin": t.name}
        for m in METRICS:
            g = gaps(v, t.name, m)
            row[f"median |{m} gap|"] = float(np.median(np.abs(g))) if len(g) else math.nan
        for m in ("MOTA", "IDF1"):
            tau = taus(v, t.name, m)
            row[f"mean tau {m}"] = float(np.nanmean(tau)) if np.isfinite(tau).any() else math.nan
        rows.append(row)
    return rows


def cell(value) -> str:
    """One Markdown table cell: a `|` inside it escaped, so that it does not split the cell."""
    return str(value).replace("|", "\\|")


def row(*cells) -> str:
    """One Markdown table row of `cells`, each escaped by `cell`."""
    return "| " + " | ".join(cell(c) for c in cells) + " |"


def markdown(v: Validation) -> str:
    """The check's tables: the summary against the goals, per-sequence metrics, the detector statistics."""
    head = [row("twin", "median abs MOTA gap (points)", "median abs IDF1 gap (points)", "median abs IDSW gap",
                "mean Kendall tau, MOTA", "mean Kendall tau, IDF1"), "|---|---:|---:|---:|---:|---:|"]
    for r in summary(v):
        head.append(row(r["twin"], f"{r['median |MOTA gap|']:.1f}", f"{r['median |IDF1 gap|']:.1f}",
                        f"{r['median |IDSW gap|']:.1f}", f"{r['mean tau MOTA']:.2f}", f"{r['mean tau IDF1']:.2f}"))
    goal = (f"Goals: median |MOTA gap| <= {GOALS['MOTA']:g}, median |IDF1 gap| <= {GOALS['IDF1']:g}, mean tau >= "
            f"{GOALS['tau']:g}; twins are the mean of {v.seeds} seeds.")
    parts = ["\n".join(head), goal]
    for m in METRICS:
        fmt = (lambda x: f"{x:.1f}") if m == "IDSW" else (lambda x: f"{100 * x:.1f}")
        lines = [row("sequence", "tracker", f"{m} real", *(t.name for t in v.twins)),
                 "|---|---|---:|" + "---:|" * len(v.twins)]
        for s in v.sequences:
            for tr in v.trackers:
                if (s, tr) not in v.real:
                    continue
                cells = [fmt(v.twin[t.name, s, tr][m]) if (t.name, s, tr) in v.twin else "failed" for t in v.twins]
                lines.append(row(s, tr, fmt(v.real[s, tr][m]), *cells))
        parts.append("\n".join(lines))
    parts.append(detector_markdown(v))
    if v.failed:
        parts.append("Failed episodes:\n" + "\n".join(f"- {f}" for f in v.failed))
    return "\n\n".join(parts) + "\n"


def detector_markdown(v: Validation) -> str:
    """Per sequence, the data's detector statistics beside each same-sequence twin's, and how many lie within 10 %."""
    twins = [t.name for t in v.twins if not t.leave_one_out]
    lines = [row("sequence", "statistic", "data", *twins), "|---|---|---:|" + "---:|" * len(twins)]
    within = {t: [] for t in twins}
    for s in v.sequences:
        data = v.detector[s, "data"]
        for k in DETECTOR_STATISTICS:
            cells = []
            for t in twins:
                x = v.detector[s, t][k]
                cells.append(f"{x:.3f}")
                if k in ("P(miss | miss)", "mean miss run", "false positives per frame") and data[k] > 0:
                    within[t].append(abs(x - data[k]) <= GOALS["detector"] * data[k])
            lines.append(row(s, k, f"{data[k]:.3f}", *cells))
    counts = ", ".join(f"{t}: {sum(w)} of {len(w)}" for t, w in within.items())
    return "\n".join(lines) + (f"\n\nP(miss | miss), mean miss run and false positives per frame within 10 % of the "
                               f"data's: {counts}.")
