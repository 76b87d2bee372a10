"""`mtt-sim perf`: env step throughput, with a reference measured in the same run.

The reference is the least any frame-producing step must do: copy a background of the same size
and draw the same N filled ellipses with OpenCV. Figures are medians over repeats.
"""

from __future__ import annotations

import statistics
import time

import cv2
import numpy as np

from .env import TrackingEnv

SIZE = (640, 480)


def _env(n: int, obs_mode: str) -> TrackingEnv:
    return TrackingEnv("dense", config={"groups.0.count": n, "render.width": SIZE[0], "render.height": SIZE[1],
                                        "env.obs_mode": obs_mode, "env.max_steps": 10**6})


def _steps_per_second(env: TrackingEnv, steps: int) -> float:
    env.reset(seed=0)
    empty = {"ids": np.zeros(0, np.int64), "boxes": np.zeros((0, 4), np.float32)}
    start = time.perf_counter()
    for _ in range(steps):
        env.step(empty)
    return steps / (time.perf_counter() - start)


def _reference_per_second(env: TrackingEnv, steps: int) -> float:
    """Copy the env's background and draw its current targets as filled ellipses, `steps` times."""
    env.reset(seed=0)
    background = env.renderer.canvas[: SIZE[1], : SIZE[0]].copy()
    boxes = env.renderer.image_boxes(env.world)
    centers = np.round((boxes[:, :2] + boxes[:, 2:] / 2) * 16).astype(int).tolist()
    axes = np.maximum(np.round(boxes[:, 2:] / 2 * 16), 1).astype(int).tolist()
    colors = env.world.color.tolist()
    start = time.perf_counter()
    for _ in range(steps):
        frame = background.copy()
        for c, a, col in zip(centers, axes, colors):
            cv2.ellipse(frame, c, a, 0, 0, 360, col, -1, cv2.LINE_8, 4)
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


def report(rows: list[dict]) -> str:
    """Markdown table of `measure`'s rows."""
    out = [f"env step throughput at {SIZE[0]}x{SIZE[1]} ('dense' scenario), medians",
           "| targets | steps/s with frames | steps/s detections only | reference frames/s | step / reference |",
           "|---:|---:|---:|---:|---:|"]
    out += [f"| {r['targets']} | {r['frames_steps_per_s']:.0f} | {r['detections_steps_per_s']:.0f} | "
            f"{r['reference_per_s']:.0f} | {r['step_over_reference']:.2f}x |" for r in rows]
    return "\n".join(out)
