"""Export: an episode written as a MOTChallenge sequence folder (frames, ground truth, detections, seqinfo.ini), in
the layout `mtt_sim.real.motchallenge` describes, for tools that read the benchmark's files; a simulated scene's
camera motion beside it as gmc.txt, in BoT-SORT's GMC format, so that camera-motion compensation can be checked."""

from __future__ import annotations

import configparser
from pathlib import Path
from typing import Mapping

import cv2
import numpy as np
from tqdm import tqdm

from mtt_sim.env import TrackingEnv
from mtt_sim.lab.episode import Episode
from mtt_sim.real.layout import is_sequence
from mtt_sim.real.motchallenge import write_rows
from mtt_sim.real.sequence import read_rows


def export_episode(scenario: str, out: str | Path, seed: int = 0, steps: int | None = None,
           config: Mapping | None = None, progress: bool = False, frames: bool = True) -> dict:
    """Run `scenario` without a tracker and write its frames (unless `frames` is False), ground truth and detections
    as a sequence. Frames an earlier, longer export left in `out` are removed. A recorded sequence (with
    `sensor.model = "synthetic"`: its twin) keeps its own gt.txt, and frames only where it has images."""
    out = Path(out)
    recorded = is_sequence(scenario)
    env = TrackingEnv(scenario, config=config, obs_mode=None if recorded
                     else "frame+detections" if frames else "detections")
    (out / "gt").mkdir(parents=True, exist_ok=True)
    (out / "det").mkdir(exist_ok=True)
    for old in (out / "img1").glob("[0-9]*.jpg"):
        old.unlink()
    episode = Episode(env, seed, steps=steps)
    if "frame" in episode.obs:
        (out / "img1").mkdir(exist_ok=True)
    sc = env.config
    gt_rows, det_rows, warps = [], [], []
    with tqdm(total=episode.limit, unit="frame", desc=f"exporting {out}", disable=not progress) as bar:
        for now in episode:
            frame = now.steps + 1  # numbered from 1; after the loop, the number of frames
            if "frame" in now.obs:
                cv2.imwrite(str(out / "img1" / f"{frame:06d}.jpg"), cv2.cvtColor(now.obs["frame"], cv2.COLOR_RGB2BGR),
                            [cv2.IMWRITE_JPEG_QUALITY, 95])
            t = env.truth
            considered = t.visibility >= sc.scoring.min_visibility
            gt_rows += [(frame, int(i), *b, int(c), 1, float(v))
                        for i, b, c, v in zip(t.ids, t.boxes.tolist(), considered, t.visibility)]
            dets = now.obs["detections"][: int(now.obs["num_detections"])]
            det_rows += [(frame, -1, *d[:4], d[4], -1, -1, -1) for d in dets.tolist()]
            if hasattr(env.source, "camera_warp"):
                warps.append(env.source.camera_warp)
            bar.update()
    if recorded and env.scored:  # the recording's own ground truth, its lines as written, cut to the frames
        gt = env.source.folder / "gt" / "gt.txt"
        frames = read_rows(gt, 7)[:, 0]
        lines = [line for line in gt.read_text().splitlines() if line.strip()]
        gt_rows = [line for line, f in zip(lines, frames) if f <= frame]
        (out / "gt" / "gt.txt").write_text("".join(f"{line}\n" for line in gt_rows))
    else:
        write_rows(out / "gt" / "gt.txt", gt_rows)
    write_rows(out / "det" / "det.txt", det_rows)
    gmc = out / "gmc.txt"
    if warps:
        gmc.write_text(gmc_text(warps))
    elif gmc.exists():  # an earlier export's, of another source
        gmc.unlink()
    info = configparser.ConfigParser()
    info.optionxform = str
    name = f"{env.source.info.name}-twin" if recorded else sc.name
    width, height = env.source.image_size
    info["Sequence"] = {"name": f"{name}-seed{seed}", "imDir": "img1", "frameRate": f"{episode.info['frame_rate']:g}",
                        "seqLength": str(frame), "imWidth": str(width), "imHeight": str(height),
                        "imExt": ".jpg"}
    with (out / "seqinfo.ini").open("w") as f:
        info.write(f, space_around_delimiters=False)
    return {"frames": frame, "gt_rows": len(gt_rows), "det_rows": len(det_rows), "folder": str(out)}


def gmc_text(warps) -> str:
    """Per-frame 2x3 warps as BoT-SORT writes its GMC files: a line a frame, its 0-based index, then a00 a01 a02 a10
    a11 a12 with 6 decimals, each followed by a tab."""
    return "".join(f"{k}\t" + "".join(f"{v:.6f}\t" for v in np.ravel(w)) + "\n" for k, w in enumerate(warps))
