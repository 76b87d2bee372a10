"""Small hand-made scenarios for tests whose answers are known."""

from pathlib import Path

import numpy as np

from mtt_sim.sim import scenario
from mtt_sim.env import TrackingEnv

EXPERIMENTS = Path(__file__).resolve().parents[1] / "docs" / "experiments"  # scenes of the docs pages' experiments
# `books` before it was rebuilt for Liu et al.'s Fig. 14: a carried top book
BOOKS_WITH_DECOY = str(EXPERIMENTS / "books_with_decoy.toml")
IDEAL = {"preset": "ideal", "clutter_rate": 0.0, "merge_prob": 0.0, "fragment_prob": 0.0}


def tiny(groups=None, occluders=(), sensor=None, **tables) -> scenario.Scenario:
    """A 200x100 flat topdown scene with still, unjittered targets and an ideal detector unless told otherwise."""
    raw = {
        "name": "Tiny",
        "render": {"width": 200, "height": 100, "background": "flat", **tables.pop("render", {})},
        "sensor": {**IDEAL, **(sensor or {})},
        "groups": groups or [{"count": 1, "speed": 0.0, "accel": 0.0, "size_jitter": 0.0, "region": [0.4, 0.4, 0.6, 0.6]}],
        "occluders": list(occluders),
        **tables,
    }
    return scenario.from_mapping(raw, "tiny")


def leaving_book(steps=200) -> scenario.Scenario:
    """A textured book that runs out of the right edge of a 200x100 noisy scene and is gone for most of the episode."""
    book = {"name": "b", "count": 1, "shape": "rect", "size": [30.0, 30.0], "size_jitter": 0.0, "speed": 4.0,
            "speed_jitter": 0.0, "heading": 0.0, "heading_jitter": 0.0, "accel": 0.0, "region": [0.7, 0.5, 0.701, 0.501],
            "color": [40, 160, 60], "similarity": 1.0, "texture": "checks"}
    return tiny(groups=[book], render={"width": 200, "height": 100, "background": "noise", "noise": 3.0},
                world={"walls": False}, env={"max_steps": steps})


def still(count=1, shape="ellipse", size=(40.0, 40.0), layer=0, name="g"):
    """A group of motionless targets."""
    return {"name": name, "count": count, "shape": shape, "size": list(size), "size_jitter": 0.0, "speed": 0.0,
            "accel": 0.0, "layer": layer, "region": [0.4, 0.4, 0.6, 0.6]}


def placed(sc: scenario.Scenario, positions, seed=0) -> TrackingEnv:
    """An env reset on `sc` with its targets moved to `positions` and the observation recomputed."""
    env = TrackingEnv(sc)
    env.reset(seed=seed)
    env.source.world.place(np.asarray(positions, float))
    env.observe()
    return env


def run_tracker(spec, env_id, config=None, seed=0, obs_mode="detections"):
    """One episode of tracker `spec` on `env_id` through gym.make (or on a scenario: a Scenario or a .toml path, in a
    TrackingEnv): (the episode's metrics, the tracker)."""
    import gymnasium as gym

    import mtt_sim  # noqa: F401  (registers the env ids)
    from mtt_sim import trackers
    from mtt_sim.lab.episode import Episode

    registered = isinstance(env_id, str) and env_id.startswith("mtt_sim/")
    env = gym.make(env_id, obs_mode=obs_mode, config=config or {}) if registered else \
        TrackingEnv(env_id, config or {}, obs_mode=obs_mode)
    episode = Episode(env, seed, trackers.make(spec))
    for _ in episode:
        pass
    return env.unwrapped.metrics.summary(), episode.agent


def fail_on_two(x):
    """A pool task: raises for 2, kills its own process for 3, else doubles."""
    import os
    import signal

    if x == 2:
        raise ValueError("two is not allowed")
    if x == 3:
        os.kill(os.getpid(), signal.SIGKILL)
    return 2 * x


def write_sequence(folder, det=(), gt=None, length=None, size=(100, 80), images=False, seqinfo=True, name=None):
    """A tiny MOTChallenge sequence folder: det rows (frame, x, y, w, h, score), gt rows (frame, id, x, y, w, h,
    considered, class, visibility) or None for none, optional seqinfo.ini and img1/ frames (each a flat grey
    level that encodes its frame number)."""
    import cv2

    folder = Path(folder)
    (folder / "det").mkdir(parents=True, exist_ok=True)
    (folder / "det" / "det.txt").write_text("".join(f"{f},-1,{x!r},{y!r},{w!r},{h!r},{s!r},-1,-1,-1\n"
                                                    for f, x, y, w, h, s in det))
    if gt is not None:
        (folder / "gt").mkdir(exist_ok=True)
        (folder / "gt" / "gt.txt").write_text("".join(",".join(repr(v) if isinstance(v, float) else str(v)
                                                                for v in row) + "\n" for row in gt))
    frames = length or max([r[0] for r in det] + [r[0] for r in gt or []] + [1])
    if seqinfo:
        (folder / "seqinfo.ini").write_text(f"[Sequence]\nname={name or folder.name}\nimDir=img1\nframeRate=10\n"
                                            f"seqLength={frames}\nimWidth={size[0]}\nimHeight={size[1]}\nimExt=.png\n")
    if images:  # lossless PNG where seqinfo.ini can say so; JPEG, the default, where there is none
        (folder / "img1").mkdir(exist_ok=True)
        for f in range(1, frames + 1):
            cv2.imwrite(str(folder / "img1" / f"{f:06d}{'.png' if seqinfo else '.jpg'}"),
                        np.full((size[1], size[0], 3), 10 * f, np.uint8))
    return folder


def exit_code(argv: list[str]) -> int:
    """`mtt-sim ARGV`'s exit status, argparse's own refusals (SystemExit) included."""
    from mtt_sim import cli

    try:
        return cli.main(argv)
    except SystemExit as done:
        return done.code
