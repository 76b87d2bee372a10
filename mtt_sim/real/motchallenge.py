"""MOTChallenge interchange: write an episode as a MOT17-style sequence, read results files back and score them.

A sequence folder holds `seqinfo.ini`, `img1/000001.jpg ...`, `gt/gt.txt` and `det/det.txt`, all with 1-based
frame numbers. Rows are comma-separated:
- gt: frame, id, x, y, w, h, considered (1, or 0 for a target the scenario's scoring leaves out), class 1,
  visibility;
- det: frame, -1, x, y, w, h, confidence, -1, -1, -1;
- results (what a tracker writes): frame, id, x, y, w, h, and anything after (ignored).
Boxes are the env's pixel coordinates (top-left corner, width, height) as they are: gt, det and results share
them, so any tool that compares the files sees the same geometry the env scores.
"""

from __future__ import annotations

import configparser
from pathlib import Path
from typing import Mapping

import cv2
import numpy as np
from tqdm import tqdm

from mtt_sim.env import TrackingEnv
from mtt_sim.lab.episode import Episode
from mtt_sim.metrics import EpisodeMetrics
from mtt_sim.real.layout import is_sequence
from mtt_sim.real.sequence import Recording, by_frame, check_frames, read_rows


def export(scenario: str, out: str | Path, seed: int = 0, steps: int | None = None,
           config: Mapping | None = None, progress: bool = False) -> dict:
    """Run `scenario` without a tracker and write its frames, ground truth and detections as a sequence. Frames an
    earlier, longer export left in `out` are removed. A recorded sequence (with `sensor.model = "synthetic"`: its
    twin) keeps its own gt.txt, and frames only where it has images."""
    out = Path(out)
    recorded = is_sequence(scenario)
    env = TrackingEnv(scenario, config=config, obs_mode=None if recorded else "frame+detections")
    (out / "gt").mkdir(parents=True, exist_ok=True)
    (out / "det").mkdir(exist_ok=True)
    for old in (out / "img1").glob("[0-9]*.jpg"):
        old.unlink()
    episode = Episode(env, seed, steps=steps)
    if "frame" in episode.obs:
        (out / "img1").mkdir(exist_ok=True)
    sc = env.config
    gt_rows, det_rows = [], []
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
            bar.update()
    if recorded and env.scored:  # the recording's own ground truth, its lines as written, cut to the frames
        gt = env.source.folder / "gt" / "gt.txt"
        frames = read_rows(gt, 7)[:, 0]
        lines = [line for line in gt.read_text().splitlines() if line.strip()]
        gt_rows = [line for line, f in zip(lines, frames) if f <= frame]
        (out / "gt" / "gt.txt").write_text("".join(f"{line}\n" for line in gt_rows))
    else:
        _write_rows(out / "gt" / "gt.txt", gt_rows)
    _write_rows(out / "det" / "det.txt", det_rows)
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


def _write_rows(path: Path, rows) -> None:
    """Comma-separated rows; floats in their shortest form that reads back exactly (a float32 box or a float64 one)."""
    path.write_text("".join(",".join(repr(v) if isinstance(v, float) else str(v) for v in r) + "\n" for r in rows))


def per_frame(rows: np.ndarray, frames: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """(ids, boxes) for frames 1..frames from rows (frame, id, x, y, w, h, ...)."""
    rows, bounds = by_frame(rows, frames)
    return [(rows[a:b, 1].astype(np.int64), rows[a:b, 2:6]) for a, b in zip(bounds[:-1], bounds[1:])]


def evaluate_results(sequence_folder: str | Path, results: str | Path, benchmark: str | None = None, **scoring) -> dict:
    """Our metrics of a results file against a sequence's ground truth, scored as TrackEval scores the sequence's
    benchmark (see `mtt_sim.sequence`): the same numbers the env gives for the same tracks."""
    recording = Recording(sequence_folder, benchmark)
    if not recording.scored:
        raise FileNotFoundError(f"{Path(sequence_folder) / 'gt' / 'gt.txt'}: not found; there is no ground truth to score")
    rows = read_rows(results, 6)
    check_frames(Path(results), rows, len(recording))
    metrics = EpisodeMetrics(**scoring)
    for k, (ids, boxes) in enumerate(per_frame(rows, len(recording))):
        gt_ids, gt_boxes, scored = recording.scoring(k, boxes)
        metrics.update(gt_ids, gt_boxes, ids[scored], boxes[scored])
    return metrics.summary()


def write_results(path: str | Path, tracks_per_frame) -> None:
    """A results file from per-frame (ids, boxes): frame, id, x, y, w, h, 1, -1, -1, -1."""
    _write_rows(Path(path), [(f, int(i), *b, 1, -1, -1, -1) for f, (ids, boxes) in enumerate(tracks_per_frame, 1)
                             for i, b in zip(ids, np.asarray(boxes, float).tolist())])
