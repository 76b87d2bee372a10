"""MOTChallenge files: write a tracker's results file, read one back and score it against a sequence's ground truth.

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

from pathlib import Path

import numpy as np

from mtt_sim.metrics import EpisodeMetrics
from mtt_sim.real.sequence import Recording, by_frame, check_frames, read_rows


def write_rows(path: Path, rows) -> None:
    """Comma-separated rows; floats in their shortest form that reads back exactly (a float32 box or a float64 one)."""
    path.write_text("".join(",".join(repr(v) if isinstance(v, float) else str(v) for v in r) + "\n" for r in rows))


def per_frame(rows: np.ndarray, frames: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """(ids, boxes) for frames 1..frames from rows (frame, id, x, y, w, h, ...)."""
    rows, bounds = by_frame(rows, frames)
    return [(rows[a:b, 1].astype(np.int64), rows[a:b, 2:6]) for a, b in zip(bounds[:-1], bounds[1:])]


def evaluate_results(sequence_folder: str | Path, results: str | Path, benchmark: str | None = None, **scoring) -> dict:
    """Our metrics of a results file against a sequence's ground truth, scored as TrackEval scores the sequence's
    benchmark (see `mtt_sim.real.sequence`): the same numbers the env gives for the same tracks."""
    recording, rows = read_scored(sequence_folder, results, benchmark)
    metrics = EpisodeMetrics(**scoring)
    for k, (ids, boxes) in enumerate(per_frame(rows, len(recording))):
        gt_ids, gt_boxes, scored = recording.scoring(k, boxes)
        metrics.update(gt_ids, gt_boxes, ids[scored], boxes[scored])
    return metrics.summary()


def read_scored(sequence_folder: str | Path, results: str | Path, benchmark: str | None = None):
    """The sequence with its ground truth and the results file's rows, each checked (a clear error naming the file)."""
    recording = Recording(sequence_folder, benchmark)
    if not recording.scored:
        raise FileNotFoundError(f"{Path(sequence_folder) / 'gt' / 'gt.txt'}: not found; there is no ground truth to score")
    if not recording.truth_rows:
        raise ValueError(f"{Path(sequence_folder) / 'gt' / 'gt.txt'}: no rows: there is no ground truth to score")
    rows = read_rows(results, 6)
    check_frames(Path(results), rows, len(recording))
    return recording, rows


def write_results(path: str | Path, tracks_per_frame) -> None:
    """A results file from per-frame (ids, boxes): frame, id, x, y, w, h, 1, -1, -1, -1."""
    write_rows(Path(path), [(f, int(i), *b, 1, -1, -1, -1) for f, (ids, boxes) in enumerate(tracks_per_frame, 1)
                             for i, b in zip(ids, np.asarray(boxes, float).tolist())])
