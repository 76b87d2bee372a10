"""How people and cameras move, measured by one function whatever the source: a real sequence's ground truth, a
simulated scene, a camera trace. Real and simulated are compared by these numbers (`mtt-sim motion`).

People: per scored track, its foot point (bottom centre of the box) with gaps filled linearly, over one-second
windows, in body heights (the box's height), so that cameras of any zoom compare:
- speed: the foot point's displacement over a window, in heights per second;
- deviation: how far a constant-velocity guess one second ahead, made from the second before, lands from where the
  person is then, in heights (how unpredictable people look to a Kalman filter);
- standing: the share of windows with speed below STANDING heights per second;
- turning: the angle between successive windows' directions of travel, where both move;
- time in view: a track's length in seconds.
The camera: per frame, the 2x3 affine warp (BoT-SORT's GMC format) that maps the previous frame's pixels onto this
frame's: its translation (pixels, and as a share of the image width), rotation and scale change.
"""

from __future__ import annotations

from pathlib import Path
from typing import Iterable

import numpy as np

STANDING = 0.1  # heights per second: slower than this, a person stands


def track_rows(frames: Iterable[tuple[np.ndarray, np.ndarray]]) -> dict[int, np.ndarray]:
    """Per id, (frame, foot x, foot y, height) rows over every frame from its first to its last, from each frame's
    (ids, boxes x, y, w, h); frames where an id is missing are filled linearly between its neighbours."""
    ids, boxes, at = [], [], []
    for k, (i, b) in enumerate(frames):
        ids.append(np.asarray(i, np.int64).ravel())
        boxes.append(np.asarray(b, float).reshape(-1, 4))
        at.append(np.full(len(ids[-1]), k))
    if not ids or not sum(map(len, ids)):
        return {}
    ids, boxes, at = np.concatenate(ids), np.concatenate(boxes), np.concatenate(at)
    order = np.lexsort((at, ids))  # by id, then frame
    ids, at = ids[order], at[order]
    seen = np.c_[at, boxes[order, 0] + boxes[order, 2] / 2, boxes[order, 1] + boxes[order, 3], boxes[order, 3]]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    ends = np.r_[starts[1:], len(ids)]
    first_seen = np.argsort(order[starts], kind="stable")  # the ids in the order they first appear
    out = {}
    for i, a, b in zip(ids[starts[first_seen]].tolist(), starts[first_seen], ends[first_seen]):
        rows = seen[a:b]
        every = np.arange(rows[0, 0], rows[-1, 0] + 1)
        out[i] = np.c_[every, *(np.interp(every, rows[:, 0], rows[:, c]) for c in (1, 2, 3))] if len(every) > len(rows) \
            else rows
    return out


def window_values(frames: Iterable[tuple[np.ndarray, np.ndarray]], frame_rate: float) -> dict[str, np.ndarray]:
    """Every one-second window's speed and deviation, every turn between windows (degrees) and every track's time in
    view (seconds), from each frame's scored (ids, boxes) at `frame_rate` frames per second."""
    n = max(1, round(frame_rate))  # frames in a one-second window
    speeds, deviations, turns, stays = [], [], [], []
    for rows in track_rows(frames).values():
        stays.append(len(rows) / frame_rate)
        feet, height = rows[:, 1:3], rows[:, 3]
        if len(rows) <= n:
            continue
        move = (feet[n:] - feet[:-n]) / ((height[n:] + height[:-n]) / 2)[:, None]  # heights per second
        speeds.append(np.hypot(*move.T))
        if len(rows) > 2 * n:
            guess = 2 * feet[n:-n] - feet[:-2 * n]
            deviations.append(np.hypot(*(feet[2 * n:] - guess).T) / height[2 * n:])
            moving = (speeds[-1][n:] >= STANDING) & (speeds[-1][:-n] >= STANDING)
            angle = np.arctan2(move[:, 1], move[:, 0])
            turn = np.abs((angle[n:] - angle[:-n] + np.pi) % (2 * np.pi) - np.pi)
            turns.append(np.degrees(turn[moving]))
    joined = lambda parts: np.concatenate(parts) if parts else np.zeros(0)  # noqa: E731
    return {"speed": joined(speeds), "deviation": joined(deviations), "turning": joined(turns),
            "time in view": np.array(stays)}


def people(frames: Iterable[tuple[np.ndarray, np.ndarray]], frame_rate: float) -> dict:
    """The people's motion statistics (see the module's docstring) from each frame's scored (ids, boxes), at
    `frame_rate` frames per second: medians of speed, deviation, turning and time in view, the standing share, and
    how many tracks and windows they rest on."""
    values = window_values(frames, frame_rate)
    median = lambda v: float(np.median(v)) if len(v) else float("nan")  # noqa: E731
    speed = values["speed"]
    return {"speed": median(speed), "deviation": median(values["deviation"]),
            "standing": float(np.mean(speed < STANDING)) if len(speed) else float("nan"),
            "turning": median(values["turning"]), "time in view": median(values["time in view"]),
            "tracks": len(values["time in view"]), "windows": int(len(speed))}


def camera(warps: np.ndarray, width: float, height: float) -> dict:
    """The camera's motion from its per-frame warps (the first, the identity, left out) over a `width` x `height`
    image: the translation a frame (median and 95th percentile, in pixels and as a share of the width), the rotation a
    frame (median, degrees) and the scale change a frame (median of |scale - 1|, in percent). The translation is
    the image centre's, so that a zoom about the corner is not counted as a move."""
    w = np.asarray(warps, float)[1:]
    if not len(w):
        return {"translation median (px)": 0.0, "translation p95 (px)": 0.0, "translation median (width)": 0.0,
                "translation p95 (width)": 0.0, "rotation (deg)": 0.0, "zoom (%)": 0.0}
    centre = np.array([width / 2, height / 2, 1.0])
    shift = np.hypot(*(w @ centre - centre[:2]).T)
    scale = np.sqrt(np.abs(np.linalg.det(w[:, :, :2])))
    rotation = np.degrees(np.abs(np.arctan2(w[:, 1, 0], w[:, 0, 0])))
    median, p95 = float(np.median(shift)), float(np.percentile(shift, 95))
    return {"translation median (px)": median, "translation p95 (px)": p95,
            "translation median (width)": median / width, "translation p95 (width)": p95 / width,
            "rotation (deg)": float(np.median(rotation)), "zoom (%)": float(np.median(np.abs(scale - 1)) * 100)}


def overrides_for(source: str, config: dict | None) -> dict:
    """The overrides a source is measured with: a scenario's as given; a sequence is read through its twin (only its
    ground truth is measured, so it need not have det/det.txt), and scene keys (walk.*, world.*) do not apply."""
    from mtt_sim.real.layout import is_sequence

    if not is_sequence(source):
        return dict(config or {})
    return {"sensor.model": "synthetic", **{k: v for k, v in (config or {}).items()
                                           if k.split(".")[0] in ("env", "scoring")}}


def scored_frames(source: str, config: dict | None = None, seed: int = 0, steps: int | None = None,
                  warps: list | None = None):
    """Each frame's scored (ids, boxes) of `source` (a scenario, a .toml file or a sequence folder) over one episode
    without a tracker with `config` (see `overrides_for`), and its frame rate and image size. A simulated scene's
    camera warps, frame by frame, are appended to `warps` where it is given."""
    from mtt_sim.env import TrackingEnv  # heavy: imported where needed
    from mtt_sim.lab.episode import Episode

    env = TrackingEnv(source, config=overrides_for(source, config), obs_mode="detections")
    no_tracks, frames = np.zeros((0, 4)), []
    for _ in Episode(env, seed, steps=steps):
        truth = env.source.scored_truth(no_tracks)
        frames.append((truth.ids, truth.boxes))
        if warps is not None and hasattr(env.source, "camera_warp"):
            warps.append(env.source.camera_warp)
    return frames, env.source.frame_rate, env.source.image_size


def markdown(table: dict[str, dict]) -> str:
    """Statistics by name (a row each) as a Markdown table."""
    columns = list(next(iter(table.values())))
    cell = lambda v: f"{v:.3g}" if isinstance(v, float) else str(v)  # noqa: E731
    lines = ["| | " + " | ".join(columns) + " |", "|---|" + "---:|" * len(columns)]
    return "\n".join(lines + [f"| {name} | " + " | ".join(cell(row[c]) for c in columns) + " |"
                              for name, row in table.items()])


def plot(values: dict[str, dict[str, np.ndarray]], path: str | Path) -> None:
    """The distributions of speed and deviation, one line per source (cumulative shares)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, key, unit in ((axes[0], "speed", "heights per second"), (axes[1], "deviation", "heights")):
        for name, v in values.items():
            if len(v[key]):
                ax.plot(np.sort(v[key]), np.linspace(0, 1, len(v[key])), label=name)
        ax.set_xscale("symlog", linthresh=0.01)
        ax.set_xlabel(f"{key} ({unit})")
        ax.set_ylabel("share of one-second windows")
        ax.grid(alpha=0.3)
    axes[0].axvline(STANDING, color="grey", ls=":", lw=1)
    axes[1].legend(fontsize=8)
    fig.suptitle("how people move: speed over one second, and the error of a constant-velocity guess one second ahead",
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
