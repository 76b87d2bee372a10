"""`mtt-sim perf`: env, metrics and tracker throughput, each with a same-run reference.

Env reference: the least any step must do to give a frame and its ground truth, copying a background of the
same size and drawing the same targets as filled ellipses into the frame and into a uint16 label map. Metrics
reference: the least a CLEAR update must do, one IoU matrix and one Hungarian assignment per frame. Trackers:
tracker time alone on recorded observations, against gnn on the same detections or a per-particle cv2.calcHist.
Figures are medians over repeats.
"""

from __future__ import annotations

import statistics
import time
import tracemalloc
from collections import Counter
from pathlib import Path

import cv2
import numpy as np
from scipy.optimize import linear_sum_assignment

from mtt_sim import trackers

from mtt_sim.lab import experiment
from mtt_sim.lab.episode import Episode
from mtt_sim.sim import scenario
from mtt_sim.env import NO_TRACKS, TrackingEnv
from mtt_sim.boxes import box_iou
from mtt_sim.metrics import EpisodeMetrics

SIZE = (640, 480)


def _env(n: int, obs_mode: str, size: tuple[int, int] = SIZE) -> TrackingEnv:
    """`dense` with n targets on a size[0] x size[1] image; above 200 targets the blobs shrink so that they cover
    the same share of the image (the physics of a jammed box would measure something else)."""
    side = max(14.0 * min(1.0, (200 / n) ** 0.5), 4.0)
    return TrackingEnv("dense", config={"groups.0.count": n, "groups.0.size": [side, side], "render.width": size[0],
                                        "render.height": size[1], "env.obs_mode": obs_mode, "env.max_steps": 10**6,
                                        "sensor.max_detections": max(256, 2 * n), "env.max_tracks": max(256, 2 * n)})


def _steps_per_second(env: TrackingEnv, steps: int) -> float:
    """Steps per second of `env` reporting no tracks, over `steps` steps from seed 0 (its first reset untimed)."""
    episode = Episode(env)
    start = time.perf_counter()
    for _ in range(steps):
        episode.answer()
        episode.advance()
        if episode.done:  # a scenario whose world ends starts again
            episode = Episode(env)
    return steps / (time.perf_counter() - start)


def _reference_per_second(env: TrackingEnv, steps: int) -> float:
    """Copy the env's background and draw its current targets as filled ellipses into a frame and into a uint16
    label map, `steps` times."""
    env.reset(seed=0)
    h, w = env.source.renderer.shape
    background = env.source.renderer.canvas[:h, :w].copy()
    boxes = env.source.renderer.image_boxes(env.source.world)
    centers = np.round((boxes[:, :2] + boxes[:, 2:] / 2) * 16).astype(int).tolist()
    axes = np.maximum(np.round(boxes[:, 2:] / 2 * 16), 1).astype(int).tolist()
    colors = env.source.world.color.tolist()
    start = time.perf_counter()
    for _ in range(steps):
        frame, labels = background.copy(), np.zeros((h, w), np.uint16)
        for i, (c, a, col) in enumerate(zip(centers, axes, colors)):
            cv2.ellipse(frame, c, a, 0, 0, 360, col, -1, cv2.LINE_8, 4)
            cv2.ellipse(labels, c, a, 0, 0, 360, i + 1, -1, cv2.LINE_8, 4)
    return steps / (time.perf_counter() - start)


def measure(repeats: int = 5, steps: int = 200) -> list[dict]:
    """One row per target count: medians of steps/s (frames, detections only), reference frames/s and the ratio."""
    rows = []
    for n in (20, 200):
        k = steps if n <= 20 else max(steps // 4, 10)
        frames_env, det_env = _env(n, "frame+detections"), _env(n, "detections")
        runs = [(_steps_per_second(frames_env, k), _steps_per_second(det_env, k), _reference_per_second(frames_env, k))
                for _ in range(repeats)]
        env_fps, det_fps, ref_fps = (statistics.median(r[i] for r in runs) for i in range(3))
        rows.append({"targets": n, "frames_steps_per_s": env_fps, "detections_steps_per_s": det_fps,
                     "reference_per_s": ref_fps, "step_over_reference": ref_fps / env_fps})
    return rows


def markdown_table(title: str, columns: list[str], rows: list[list], left: int = 0) -> str:
    """A markdown table under a title line; the first `left` columns are aligned left, the others right."""
    lines = [title, "| " + " | ".join(columns) + " |",
             "|" + "|".join("---" if i < left else "---:" for i in range(len(columns))) + "|"]
    return "\n".join(lines + ["| " + " | ".join(map(str, row)) + " |" for row in rows])


def report(rows: list[dict]) -> str:
    """Markdown table of `measure`'s rows."""
    return markdown_table(f"env step throughput at {SIZE[0]}x{SIZE[1]} ('dense' scenario), medians; reference: background "
                  "copy and two filled ellipses per target (frame and label map)",
                  ["targets", "steps/s with frames", "steps/s detections only", "reference frames/s",
                   "step / reference"],
                  [[r["targets"], f"{r['frames_steps_per_s']:.0f}", f"{r['detections_steps_per_s']:.0f}",
                    f"{r['reference_per_s']:.0f}", f"{r['step_over_reference']:.2f}x"] for r in rows])


def measure_scenarios(repeats: int = 5, steps: int = 200) -> list[dict]:
    """Every shipped scenario's steps/s with frames (seed 0, no tracks), against the reference drawing its own
    targets of the first frame."""
    rows = []
    for key in sorted(scenario.available()):
        env = TrackingEnv(key, config={"env.max_steps": 10**6})
        runs = [(_steps_per_second(env, steps), _reference_per_second(env, steps)) for _ in range(repeats)]
        fps, ref = (statistics.median(r[i] for r in runs) for i in range(2))
        h, w = env.source.renderer.shape
        rows.append({"scenario": key, "image": f"{w}x{h}", "targets": len(env.source.world.ids), "steps_per_s": fps,
                     "reference_per_s": ref, "step_over_reference": ref / fps})
    return rows


def report_scenarios(rows: list[dict]) -> str:
    return markdown_table("env step throughput per scenario with frames and detections, medians (reference: as above, its "
                  "own targets of the first frame)",
                  ["scenario", "image", "targets (first frame)", "steps/s", "reference frames/s", "step / reference"],
                  [[r["scenario"], r["image"], r["targets"], f"{r['steps_per_s']:.0f}", f"{r['reference_per_s']:.0f}",
                    f"{r['step_over_reference']:.2f}x"] for r in rows], left=2)


STAGES = ("world", "render", "truth", "detector", "scoring", "other")


def stage_seconds(env: TrackingEnv, steps: int) -> dict[str, float]:
    """Seconds per step of each stage of env.step, timed by wrapping the env's parts: the world's physics and motion,
    the renderer (frame and label map), the truth's visibility, the detector, the scoring and the rest."""
    spent: Counter = Counter()

    def timed(name, fn):
        def run(*args, **kwargs):
            start = time.perf_counter()
            out = fn(*args, **kwargs)
            spent[name] += time.perf_counter() - start
            return out
        return run

    env.reset(seed=0)
    scene = env.source
    scene.world.step = timed("world", scene.world.step)
    scene.renderer.render = timed("render", scene.renderer.render)
    scene.measure = timed("truth", scene.measure)
    scene.sensor.detect = timed("detector", scene.sensor.detect)
    env.metrics.update = timed("scoring", env.metrics.update)
    start = time.perf_counter()
    for _ in range(steps):
        env.step(NO_TRACKS)
    total = time.perf_counter() - start
    spent["other"] = total - sum(spent.values())
    return {name: spent[name] / steps for name in STAGES} | {"total": total / steps}


def measure_scaling(repeats: int = 5, steps: int = 100) -> list[dict]:
    """Milliseconds per step of each stage, medians, at 20, 200 and 2000 targets on 640x480 and 1920x1080 frames."""
    rows = []
    for size in (SIZE, (1920, 1080)):
        for n in (20, 200, 2000):
            env = _env(n, "frame+detections", size)
            runs = [stage_seconds(env, max(int(steps * (20 / n) ** 0.5), 10)) for _ in range(repeats)]
            rows.append({"targets": n, "image": f"{size[0]}x{size[1]}", "pixels": size[0] * size[1],
                         **{k: statistics.median(r[k] for r in runs) * 1e3 for k in (*STAGES, "total")}})
    return rows


def _growth(a: dict, b: dict) -> str:
    """Each stage's cost ratio from row a to row b."""
    return ", ".join(f"{k} {b[k] / a[k]:.1f}x" for k in (*STAGES, "total") if a[k] > 0)


def report_scaling(rows: list[dict]) -> str:
    by = {(r["targets"], r["image"]): r for r in rows}
    small, large = f"{SIZE[0]}x{SIZE[1]}", "1920x1080"
    pixels = by[(200, large)]["pixels"] / by[(200, small)]["pixels"]
    return "\n".join([
        markdown_table("env step cost by stage, milliseconds per step with frames, medians ('dense'; above 200 targets the "
               "blobs shrink to keep the share of the image they cover)", ["targets", "image", "steps/s", *STAGES],
               [[r["targets"], r["image"], f"{1e3 / r['total']:.0f}", *(f"{r[k]:.2f}" for k in STAGES)] for r in rows]),
        f"growth, 200 -> 2000 targets (10x) at {small}: " + _growth(by[(200, small)], by[(2000, small)]),
        f"growth, {small} -> {large} ({pixels:.2f}x the pixels) at 200 targets: "
        + _growth(by[(200, small)], by[(200, large)])])


def _sequence(n: int, frames: int, seed: int = 0):
    """A synthetic sequence: n targets drifting, tracks with noise, a few swapped ids and misses."""
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0, 600, (n, 2))
    out = []
    for _ in range(frames):
        pos += rng.normal(0, 2, pos.shape)
        gt = np.c_[pos, np.full((n, 2), 24.0)]
        keep = rng.random(n) < 0.9
        trk = gt[keep] + rng.normal(0, 2, (keep.sum(), 4)) * [1, 1, 0.2, 0.2]
        ids = np.flatnonzero(keep)
        ids = np.where(rng.random(len(ids)) < 0.02, ids + 1000, ids)
        out.append((np.arange(n), gt, ids, trk))
    return out


def _time(fn) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def measure_metrics(repeats: int = 5) -> list[dict]:
    """Medians of EpisodeMetrics.update per frame (20 and 200 objects) and of the summary of 1000 x 20."""
    rows = []
    for n, frames in ((20, 1000), (200, 100)):
        seq = _sequence(n, frames)
        runs = []
        for _ in range(repeats):
            m = EpisodeMetrics()
            upd = _time(lambda: [m.update(*f) for f in seq]) / frames
            ref = _time(lambda: [linear_sum_assignment(box_iou(f[1], f[3]), maximize=True) for f in seq]) / frames
            summ = _time(m.summary)
            runs.append((upd, ref, summ))
        upd, ref, summ = (statistics.median(r[i] for r in runs) for i in range(3))
        rows.append({"objects": n, "frames": frames, "update_us": upd * 1e6, "reference_us": ref * 1e6,
                     "update_over_reference": upd / ref, "summary_s": summ})
    return rows


def report_metrics(rows: list[dict]) -> str:
    """Markdown table of `measure_metrics`' rows."""
    return markdown_table("EpisodeMetrics cost, medians (reference: IoU matrix + one Hungarian assignment per frame)",
                  ["objects", "frames", "update per frame", "reference per frame", "update / reference",
                   "summary of all frames"],
                  [[r["objects"], r["frames"], f"{r['update_us']:.0f} us", f"{r['reference_us']:.0f} us",
                    f"{r['update_over_reference']:.2f}x", f"{r['summary_s'] * 1e3:.1f} ms"] for r in rows])


def measure_metrics_memory(repeats: int = 5, objects: int = 200, frames: int = 3000) -> dict:
    """What a long episode's metrics keep: bytes stored per frame, the summary's median time and its peak memory
    (tracemalloc, in one more run) over what is stored."""
    seq = _sequence(objects, 1000)
    m = EpisodeMetrics()
    for k in range(frames):
        m.update(*seq[k % len(seq)])
    stored = m.stored_bytes()
    summary_s = statistics.median(_time(m.summary) for _ in range(repeats))
    tracemalloc.start()
    m.summary()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return {"objects": objects, "frames": frames, "kb_per_frame": stored / frames / 1024, "summary_s": summary_s,
            "peak_over_stored": peak / stored}


def report_metrics_memory(row: dict) -> str:
    return markdown_table("EpisodeMetrics memory of a long episode (summary time: median)",
                  ["objects", "frames", "stored per frame", "summary", "summary peak / stored"],
                  [[row["objects"], row["frames"], f"{row['kb_per_frame']:.1f} KB", f"{row['summary_s']:.2f} s",
                    f"{row['peak_over_stored']:.2f}x"]])


def _recorded_detections(n: int, frames: int, clutter: float = 5.0, with_frames: bool = False):
    """env.reset's info and the observations of `n` targets with P_D = 0.9 and Poisson clutter, recorded once."""
    config = {"groups.0.count": n, "sensor.pd": 0.9, "sensor.clutter_rate": clutter, "sensor.min_visibility": 0.0}
    return _recorded("clutter_storm", frames, config, "frame+detections" if with_frames else "detections")


def _ms_per_frame(spec: str, recorded: tuple[dict, list[dict]]) -> float:
    info, observations = recorded
    tracker = trackers.make(spec)
    tracker.reset(info)
    return _time(lambda: [tracker.update(o) for o in observations]) / len(observations) * 1e3


def measure_jpda(repeats: int = 5, frames: int = 150) -> list[dict]:
    """Medians of jpda's milliseconds per frame (tracker time only) at 10, 20 and 50 targets, against gnn."""
    rows = []
    for n in (10, 20, 50):
        rec = _recorded_detections(n, frames)
        runs = [(_ms_per_frame("jpda", rec), _ms_per_frame("gnn", rec)) for _ in range(repeats)]
        jpda, gnn = (statistics.median(r[i] for r in runs) for i in range(2))
        rows.append({"targets": n, "jpda_ms": jpda, "gnn_ms": gnn, "jpda_over_gnn": jpda / gnn})
    return rows


def report_jpda(rows: list[dict]) -> str:
    table = markdown_table("jpda tracker time per frame, medians (P_D 0.9, 5 clutter a frame, detections only; reference: gnn)",
                   ["targets", "jpda ms/frame", "gnn ms/frame", "jpda / gnn"],
                   [[r["targets"], f"{r['jpda_ms']:.2f}", f"{r['gnn_ms']:.2f}", f"{r['jpda_over_gnn']:.2f}x"]
                    for r in rows])
    return "\n".join([table, "jpda's parameters (its defaults, as measured):",
                      *("    " + line for line in trackers.base.describe("jpda"))])


def measure_lmb(repeats: int = 5, frames: int = 100) -> list[dict]:
    """Medians of lmb's milliseconds per frame (tracker time only) at 10, 30 and 100 targets with 10 clutter a
    frame, without and with re-identification, against gnn on the same detections."""
    rows = []
    for n in (10, 30, 100):
        rec = _recorded_detections(n, frames, clutter=10.0, with_frames=True)
        runs = [[_ms_per_frame(spec, rec) for spec in ("lmb:reid=false", "lmb", "gnn")] for _ in range(repeats)]
        lmb, reid, gnn = (statistics.median(r[i] for r in runs) for i in range(3))
        per_frame = float(np.mean([o["num_detections"] for o in rec[1]]))
        rows.append({"targets": n, "detections": per_frame, "lmb_ms": lmb, "lmb_reid_ms": reid, "gnn_ms": gnn,
                     "lmb_over_gnn": lmb / gnn})
    return rows


def report_lmb(rows: list[dict]) -> str:
    return markdown_table("lmb tracker time per frame, medians (P_D 0.9, 10 clutter a frame; reference: gnn on the same "
                  "detections)", ["targets", "detections/frame", "lmb:reid=false ms/frame", "lmb (re-id) ms/frame",
                                  "gnn ms/frame", "lmb:reid=false / gnn"],
                  [[r["targets"], f"{r['detections']:.1f}", f"{r['lmb_ms']:.2f}", f"{r['lmb_reid_ms']:.2f}",
                    f"{r['gnn_ms']:.2f}", f"{r['lmb_over_gnn']:.2f}x"] for r in rows])


BASELINE_PEERS = {"sort": "SORTTracker", "bytetrack": "ByteTrackTracker", "ocsort": "OCSORTTracker"}
BASELINE_WORKLOADS = (("mot17_like", {}), ("dense", {"groups.0.count": 60, "sensor.pd": 0.9,
                                                    "sensor.clutter_rate": 5.0}))


def measure_baselines(repeats: int = 5, frames: int = 300, workloads=BASELINE_WORKLOADS) -> list[dict]:
    """Medians of the published baselines' frames per second of tracker time on the recorded detections of each
    workload (a scenario or sequence folder, and its config), beside Roboflow's same tracker (its update() on
    supervision Detections built beforehand) where its package is installed (the [peers] extra), in the same run."""
    try:
        package = trackers.adapters.roboflow.roboflow_package()
        from supervision import Detections
    except ImportError:
        package = None
    rows = []
    for source, config in workloads:
        rec = _recorded(source, frames, config, "detections")
        n = len(rec[1])
        for ours, theirs in BASELINE_PEERS.items():
            runs = []
            for _ in range(repeats):
                peer = float("nan")
                if package is not None:
                    model = getattr(package, theirs)()
                    dets = [trackers.adapters.roboflow.as_detections(Detections, trackers.base.detections(o)) for o in rec[1]]
                    peer = n / _time(lambda: [model.update(d) for d in dets])
                runs.append((1e3 / _ms_per_frame(ours, rec), peer))
            fps, peer = (statistics.median(r[i] for r in runs) for i in range(2))
            rows.append({"tracker": ours, "workload": Path(str(source)).name, "fps": fps, "roboflow_fps": peer})
    return rows


def report_baselines(rows: list[dict]) -> str:
    peer = not all(np.isnan(r["roboflow_fps"]) for r in rows)
    return markdown_table("published baselines, tracker time only, medians (reference: Roboflow's same tracker, "
                  + ("trackers " + metadata_version("trackers") if peer else "not installed: the [peers] extra")
                  + ")", ["tracker", "workload", "frames/s", "Roboflow frames/s", "ours / Roboflow"],
                  [[r["tracker"], r["workload"], f"{r['fps']:.0f}"]
                   + ([f"{r['roboflow_fps']:.0f}", f"{r['fps'] / r['roboflow_fps']:.2f}x"] if peer else ["", ""])
                   for r in rows], left=2)


def metadata_version(package: str) -> str:
    from importlib import metadata

    return metadata.version(package)


RFS_WORKLOADS = (("mot17_like", {}, ("gmphd",)),
                 ("dense", {"groups.0.count": 100, "sensor.pd": 0.9, "sensor.clutter_rate": 10.0},
                  ("gmphd", "lmb:reid=false", "lmb")))


def measure_rfs(repeats: int = 5, frames: int = 100) -> list[dict]:
    """Medians of the random-finite-set trackers' milliseconds per frame (tracker time only) on scenarios: gmphd on
    mot17_like; gmphd and lmb on dense with 100 targets, P_D 0.9 and 10 clutter a frame; each against gnn."""
    rows = []
    for key, config, specs in RFS_WORKLOADS:
        rec = _recorded(key, frames, config)
        runs = [[_ms_per_frame(spec, rec) for spec in (*specs, "gnn")] for _ in range(repeats)]
        gnn = statistics.median(r[-1] for r in runs)
        setting = ", ".join(f"{k.split('.')[-1]}={v}" for k, v in config.items())
        for i, spec in enumerate(specs):
            ms = statistics.median(r[i] for r in runs)
            rows.append({"tracker": spec, "workload": key + (f" ({setting})" if setting else ""), "ms": ms,
                         "gnn_ms": gnn, "over_gnn": ms / gnn})
    return rows


def report_rfs(rows: list[dict]) -> str:
    return markdown_table("random-finite-set trackers on scenarios, tracker time only, medians (reference: gnn on the same "
                  "detections)", ["tracker", "workload", "ms/frame", "frames/s", "gnn ms/frame", "tracker / gnn"],
                  [[r["tracker"], r["workload"], f"{r['ms']:.2f}", f"{1e3 / r['ms']:.0f}", f"{r['gnn_ms']:.2f}",
                    f"{r['over_gnn']:.2f}x"] for r in rows], left=2)


def _recorded(scenario: str, frames: int, config: dict | None = None,
              obs_mode: str = "frame+detections") -> tuple[dict, list[dict]]:
    """env.reset's info and `frames` observations of `scenario` (seed 0, no tracks), for timing trackers alone."""
    env = TrackingEnv(scenario, config={**(config or {}), "env.max_steps": frames}, obs_mode=obs_mode)
    episode = Episode(env)
    return episode.info, [{k: v.copy() if hasattr(v, "copy") else v for k, v in now.obs.items()} for now in episode]


def _particle_filter_row(label: str, spec: str, scenario: str, targets: int, particles: int, reference, repeats: int,
                         frames: int, config: dict | None = None) -> dict:
    """Frames per second of `spec` on the first `targets` hand-initialised targets, against `reference(obs, boxes)`:
    the per-particle way, one cv2.calcHist call per particle region."""
    info, recorded = _recorded(scenario, frames, config)
    first = {**info, "init_ids": info["init_ids"][:targets], "init_boxes": info["init_boxes"][:targets]}
    boxes = np.round(first["init_boxes"]).astype(int)

    def tracker_run():
        tracker = trackers.make(spec, particles=particles)
        tracker.reset(first)
        for o in recorded:
            tracker.update(o)

    def per_particle():
        for o in recorded:
            reference(o["frame"], boxes, particles)

    runs = [(frames / _time(tracker_run), frames / _time(per_particle)) for _ in range(repeats)]
    fps, ref = (statistics.median(r[i] for r in runs) for i in range(2))
    return {"tracker": label.format(targets=len(boxes)), "fps": fps, "reference_fps": ref}


def _rgb_calchist(frame, boxes, particles):
    for x, y, w, h in boxes:
        for _ in range(particles):
            cv2.calcHist([frame[y:y + h, x:x + w]], [0, 1, 2], None, [16, 16, 16], [0, 256] * 3)


def _hs_calchist(frame, boxes, particles):
    hsv = cv2.cvtColor(frame, cv2.COLOR_RGB2HSV)
    for x, y, w, h in boxes:
        for _ in range(particles):
            cv2.calcHist([hsv[y:y + h, x:x + w]], [0, 1], None, [16, 16], [0, 180, 0, 256])


CROWD = {"groups.0.count": 30, "groups.1.count": 10}  # mot17_like with at least 30 people in the first frame


def measure_pf(repeats: int = 5, frames: int = 60) -> list[dict]:
    """The particle filters' frames per second (tracker time only): pf with one target and 60 particles on 768x576
    umbrella frames, ipf with 4 books x 100 particles on 640x480, and both with 30 people of mot17_like (960x540);
    each against one cv2.calcHist per particle of its histogram alone (RGB 16^3 for pf, H-S 16x16 for ipf)."""
    crowd = max(frames // 4, 2)
    return [_particle_filter_row("pf (Li et al. 2007), 1 x 60 particles, 768x576", "pf", "umbrellas", 1, 60,
                                 _rgb_calchist, repeats, frames),
            _particle_filter_row("ipf (Liu et al. 2011), 4 x 100 particles, 640x480", "ipf", "books", 4, 100,
                                 _hs_calchist, repeats, frames),
            _particle_filter_row("pf, {targets} x 60 particles, mot17_like 960x540", "pf", "mot17_like", 30, 60,
                                 _rgb_calchist, repeats, crowd, CROWD),
            _particle_filter_row("ipf, {targets} x 100 particles, mot17_like 960x540", "ipf", "mot17_like", 30, 100,
                                 _hs_calchist, repeats, crowd, CROWD)]


def report_pf(rows: list[dict]) -> str:
    return markdown_table("particle filters, tracker time only, medians",
                  ["tracker", "frames/s", "per-particle calcHist frames/s (its histogram only)", "tracker / reference"],
                  [[r["tracker"], f"{r['fps']:.0f}", f"{r['reference_fps']:.0f}",
                    f"{r['fps'] / r['reference_fps']:.2f}x"] for r in rows], left=1)


SWEEP = (("sort", "gnn"), ("crossing", "soccer", "mot17_like"), 4)  # trackers, scenarios, seeds: 24 full episodes


def measure_sweeps(repeats: int = 3, config: dict | None = None) -> dict:
    """Medians of the wall time of one `bench` grid (SWEEP, with `config` overrides) on one worker and on two local
    worker processes (at most 3 repeats: a grid takes a minute)."""
    specs, scenarios, seeds = SWEEP
    runs = [[_time(lambda: experiment.run_grid(specs, scenarios, seeds, config, workers=w)) for w in (1, 2)]
            for _ in range(min(repeats, 3))]
    one, two = (statistics.median(r[i] for r in runs) for i in range(2))
    return {"episodes": len(specs) * len(scenarios) * seeds, "one_s": one, "two_s": two, "speedup": one / two}


def report_sweeps(row: dict) -> str:
    specs, scenarios, seeds = SWEEP
    return markdown_table(f"bench grid ({', '.join(specs)} on {', '.join(scenarios)}, {seeds} seeds: {row['episodes']} "
                  "episodes), wall time, medians", ["1 worker", "2 workers", "speed-up"],
                  [[f"{row['one_s']:.1f} s", f"{row['two_s']:.1f} s", f"{row['speedup']:.2f}x"]])
