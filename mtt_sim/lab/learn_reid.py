"""`mtt-sim learn-reid`: learn the XQDA re-identification metric of the LMB tracker (Jiang and Yang) from crops the
simulator renders.

The same target at two times is one class. Crops come from the ground-truth boxes of well-visible targets every
few frames of training episodes (seeds far from the 0..9 of the experiments), so the metric learns what changes
with time in our world (lighting drift, noise, blur, gait, size with depth) and what tells targets apart.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from tqdm import tqdm

from mtt_sim.trackers.parts import reid

from mtt_sim.env import TrackingEnv
from mtt_sim.lab.episode import Episode


def training_crops(scenario: str, seeds, frames: int, every: int, min_visibility: float = 0.9,
                   min_height: float = 24.0, progress: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """LOMO features and class numbers (one per target and episode) of the training crops."""
    features, classes = [], []
    bar = tqdm(total=len(seeds) * frames, unit="frame", desc="rendering crops", disable=not progress)
    for seed in seeds:
        env = TrackingEnv(scenario, config={"env.max_steps": frames})
        for now in Episode(env, seed):
            if now.steps % every == 0:
                t = env.truth
                keep = (t.visibility >= min_visibility) & (t.boxes[:, 3] >= min_height)
                features.extend(reid.lomo(reid.crops(now.obs["frame"], t.boxes[keep])))
                classes.extend(seed * 1_000_000 + t.ids[keep].astype(int))
            bar.update()
    bar.close()
    return np.array(features), np.array(classes)


def learn(out: str | Path, scenario: str = "mot17_like", seeds=range(1000, 1004), frames: int = 300, every: int = 15,
          dims: int = 16, progress: bool = False) -> dict:
    """Learn the metric and save it at `out` (reid.METRIC_FILE is the file the package ships); returns a summary."""
    features, classes = training_crops(scenario, seeds, frames, every, progress=progress)
    if len(np.unique(classes)) < 2:
        raise ValueError(f"learn-reid: {len(features)} crops of {len(np.unique(classes))} targets are too few to learn "
                         "from; use more seeds or frames")
    arrays = reid.learn_xqda(features, classes, dims=dims)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(out, **{k: v.astype(np.float16) if k == "projection" else v for k, v in arrays.items()})
    return {"crops": len(features), "classes": len(np.unique(classes)), "feature_size": features.shape[1],
            "dims": dims, "file": str(out), "bytes": out.stat().st_size}
