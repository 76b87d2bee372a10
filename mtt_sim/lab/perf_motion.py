"""What the world that moves like the real one costs (`mtt-sim perf --sections motion`): each stage of an env step
on `mot17_like` with its earlier walkers, with the fitted walking model and with a camera going forward (its flow
moves everyone each step but the people who walk with it), and on `mot17_moving` with a steady pan and with the
fitted walking camera, so that the walkers' cost is read beside the render's."""

from __future__ import annotations

import statistics

from mtt_sim.env import TrackingEnv
from mtt_sim.lab.perf import STAGES, markdown_table, stage_seconds

CASES = (("mot17_like", "walkers before (walk.model = off)", {"walk.model": "off"}),
         ("mot17_like", "fitted walkers (as shipped)", {}),
         ("mot17_like", "fitted walkers, camera going forward", {"render.camera_forward": 0.3}),
         ("mot17_like", "the same, 3 people walking with the camera",
          {"render.camera_forward": 0.3, "render.camera_companions": 3}),
         ("mot17_moving", "fitted walkers, steady pan", {"render.camera": "pan", "render.pan_speed": [1.5, 0.0]}),
         ("mot17_moving", "fitted walkers, walking camera (as shipped)", {}))


def measure_motion(repeats: int = 5, steps: int = 200) -> list[dict]:
    """Milliseconds per step of each stage (medians over `repeats`), with frames, seed 0, no tracks."""
    rows = []
    for key, what, config in CASES:
        env = TrackingEnv(key, config={"env.max_steps": 10**6, **config})
        runs = [stage_seconds(env, steps) for _ in range(repeats)]
        rows.append({"scenario": key, "motion": what,
                     **{k: statistics.median(r[k] for r in runs) * 1e3 for k in (*STAGES, "total")}})
    return rows


def report_motion(rows: list[dict]) -> str:
    return markdown_table("env step cost by stage with the walking model and the fitted cameras, milliseconds per "
                          "step with frames, medians", ["scenario", "motion", "steps/s", *STAGES],
                          [[r["scenario"], r["motion"], f"{1e3 / r['total']:.0f}", *(f"{r[k]:.2f}" for k in STAGES)]
                           for r in rows], left=2)
