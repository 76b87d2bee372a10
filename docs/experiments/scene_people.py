"""Who a fitted scene scores and where its people leave, against the real sequence's ground truth.

For every sequence folder under DATA with a fitted scene `scene_<name>.toml` in SCENES (the work folder of
`tune_sim_to_real.py`, or any folder of `mtt-sim fit-scene` outputs so named), the sequence's ground truth (replayed
as its twin; who covers whom is measured from the boxes) and the scene's people (seeds 0 to --seeds - 1) are measured
by one function, frame by frame:
- wholly hidden: the share of the people in view with nothing of them visible (covered by nearer people);
- p95 height: the 95th percentile of their box heights, px;
- end inside: of the people whose last frame comes before the sequence's, the share whose last box lies inside the
  picture (more than 5 px from every border): people lost to occlusion or no longer annotated, not walking out;
- last height: the median height of those last boxes, px;
- ended: how many people ended so (the scene's: a mean over its seeds).

    python docs/experiments/scene_people.py ../shared/data/mot15 work/rows --seeds 2
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from mtt_sim.env import TrackingEnv
from mtt_sim.sim import scenario as scn

BORDER = 5.0  # px: a last box this close to a border walked out


def people(env, seed: int) -> tuple[list, tuple[int, int]]:
    """Each frame's (ids, boxes, visibility) of everyone in view in one episode of `env`, and the image size."""
    env.reset(seed=seed)
    rows = env.action_space["ids"].shape[0]
    nothing = {"boxes": np.zeros((rows, 4), np.float32), "ids": np.zeros(rows, np.int64), "num_tracks": 0}
    frames, done = [], False
    while not done:
        t = env.unwrapped.truth
        frames.append((t.ids.copy(), t.boxes.copy(), t.visibility.copy()))
        done = any(env.step(nothing)[2:4])
    return frames, env.unwrapped.source.image_size


def twin(folder) -> TrackingEnv:
    """A sequence's ground truth replayed through the synthetic detector (what it detects does not matter here: only
    who is in view, and who covers whom)."""
    return TrackingEnv(sequence=str(folder), config={"sensor.model": "synthetic"}, obs_mode="detections")


def measure(frames: list, size: tuple[int, int]) -> dict:
    """The statistics of the module's docstring over `frames`."""
    ids = np.concatenate([i for i, _, _ in frames])
    boxes = np.concatenate([b for _, b, _ in frames]).reshape(-1, 4)
    visibility = np.concatenate([v for _, _, v in frames])
    frame = np.repeat(np.arange(len(frames)), [len(i) for i, _, _ in frames])
    last = len(ids) - 1 - np.unique(ids[::-1], return_index=True)[1]  # each person's last row
    ends = boxes[last[frame[last] < len(frames) - 1]]
    heights = boxes[:, 3]
    w, h = size
    inside = ((ends[:, 0] > BORDER) & (ends[:, 1] > BORDER) & (ends[:, 0] + ends[:, 2] < w - BORDER)
              & (ends[:, 1] + ends[:, 3] < h - BORDER))
    return {"hidden": float(np.mean(visibility <= 0)), "p95": float(np.percentile(heights, 95)),
            "inside": float(np.mean(inside)) if len(ends) else float("nan"),
            "last": float(np.median(ends[:, 3])) if len(ends) else float("nan"), "ended": len(ends)}


def pooled(runs: list[dict]) -> dict:
    """Seeds' statistics averaged."""
    return {k: float(np.mean([r[k] for r in runs])) for k in runs[0]}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data", help="a folder of MOTChallenge sequence folders (gt/gt.txt)")
    p.add_argument("scenes", help="a folder of fitted scenes named scene_<sequence>.toml")
    p.add_argument("--seeds", type=int, default=2, help="the scene's seeds (default 2)")
    args = p.parse_args()
    print("| sequence | wholly hidden: real / scene | p95 height, px | end inside | last height, px | ended |")
    print("|---|---:|---:|---:|---:|---:|")
    for folder in sorted(f for f in Path(args.data).iterdir() if (f / "gt" / "gt.txt").is_file()):
        scene = Path(args.scenes) / f"scene_{folder.name}.toml"
        if not scene.is_file():
            continue
        real = measure(*people(twin(folder), 0))
        sim = pooled([measure(*people(TrackingEnv(scn.load(scene), obs_mode="detections"), s))
                      for s in range(args.seeds)])
        print(f"| {folder.name} | {real['hidden']:.2f} / {sim['hidden']:.2f} | {real['p95']:.0f} / {sim['p95']:.0f} | "
              f"{real['inside']:.2f} / {sim['inside']:.2f} | {real['last']:.0f} / {sim['last']:.0f} | "
              f"{real['ended']} / {sim['ended']:.1f} |", flush=True)


if __name__ == "__main__":
    main()
