"""Issue 38's first goal, measured: does a label-free fitted scene move like the real sequence's people?

For every sequence folder under DATA (MOTChallenge layout: det/det.txt, gt/gt.txt, seqinfo.ini), `mtt-sim fit-scene`'s
fit (detections alone, detector from --sensor) is written as a scenario and run without a tracker at its own frame
rate (seeds 0 to 3); its scored truth and the sequence's ground truth are measured by one function
(`mtt_sim.sim2real.motion.people`): the median speed and one-second deviation (body heights) and the standing share.
The goal: the scene's speed and deviation within 0.67-1.5x of the real people's and its standing share within 0.1 of
theirs. The scene's statistic is measured over its seeds pooled (what the scene is, not one draw of it); the table
also gives each seed's value and counts the sequences where every seed alone meets the goal, for a scene of a few
people over a few seconds moves from draw to draw by more than the goal's margins (so does the real one, a single
draw). A second table gives the crowd: people a frame and their median time in view.

    python docs/experiments/fit_scene_motion.py ../shared/data/mot15 --sensor fitted.toml

(the sensor from `mtt-sim calibrate ../shared/data/mot15/*/ --out fitted.toml`). Run it on an older checkout with
PYTHONPATH=that-checkout to measure the fit-scene of before.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

from mtt_sim.sim import scenario as scn
from mtt_sim.sim2real import fit_scene, motion

SEEDS = (0, 1, 2, 3)
OFFSET = 10**7  # seed k's ids are shifted by k OFFSET, so that pooled seeds keep their tracks apart
RATIO = (0.67, 1.5)
STANDING_GAP = 0.1


def measure(folder: Path, sensor: str, scratch: Path) -> dict:
    frames, rate, _ = motion.scored_frames(str(folder))
    real = {**motion.people(frames, rate), "crowd": crowd(frames)}
    raw = fit_scene.fit_scene(folder, sensor, seeds=())[0]
    path = scratch / f"{folder.name}.toml"
    path.write_text(scn.to_toml(raw, [f"fitted to {folder.name}"]))
    scene, pooled = [], []
    for seed in SEEDS:
        frames, scene_rate, _ = motion.scored_frames(str(path), seed=seed)
        scene.append(motion.people(frames, scene_rate))
        pooled += [(ids + seed * OFFSET, boxes) for ids, boxes in frames]
    render, walk = raw.get("render", {}), raw.get("walk", {})
    return {"real": real, "scene": scene, "pooled": {**motion.people(pooled, scene_rate), "crowd": crowd(pooled)},
            "rate": raw.get("world", {}).get("frame_rate", 25.0),
            "camera": render.get("camera", "static") + (f", forward {render['camera_forward']:g}/s"
                                                        if render.get("camera_forward") else ""),
            "walk": walk.get("model", "off")}


def crowd(frames) -> float:
    """The people scored a frame, on average."""
    return sum(len(ids) for ids, _ in frames) / max(len(frames), 1)


def meets(real: dict, scene: dict) -> dict:
    ratio = lambda k: scene[k] / real[k] if real[k] > 0 else float("nan")  # noqa: E731
    return {"speed": RATIO[0] <= ratio("speed") <= RATIO[1], "deviation": RATIO[0] <= ratio("deviation") <= RATIO[1],
            "standing": abs(scene["standing"] - real["standing"]) <= STANDING_GAP}


def table(results: dict) -> str:
    """Per sequence: the real value, the scene's pooled value (ratio) and its seeds' range; a mark where the pooled
    value misses the goal; the counts met pooled, by seed 0 alone (as issue 38 measured) and by every seed alone."""
    lines = ["| sequence | fps (scene) | camera | speed real / scene (ratio) [seeds] | deviation real / scene (ratio) "
             "[seeds] | standing real / scene [seeds] |", "|---|---:|---|---:|---:|---:|"]
    keys = ("speed", "deviation", "standing")
    pooled, first, every = (dict.fromkeys(keys + ("all",), 0) for _ in range(3))
    for name, r in results.items():
        real, scene, ok = r["real"], r["pooled"], meets(r["real"], r["pooled"])
        alone = {k: all(meets(real, s)[k] for s in r["scene"]) for k in keys}
        for counts, met in ((pooled, ok), (first, meets(real, r["scene"][0])), (every, alone)):
            for k in keys:
                counts[k] += met[k]
            counts["all"] += all(met[k] for k in keys)
        span = lambda k, f: f"[{f.format(min(s[k] for s in r['scene']))}-{f.format(max(s[k] for s in r['scene']))}]"  # noqa: E731
        cell = lambda k, f: (f"{f.format(real[k])} / {f.format(scene[k])}"  # noqa: E731
                             + (f" (x{scene[k] / real[k]:.2f})" if k != "standing" else "")
                             + f" {span(k, f)}" + ("" if ok[k] else " ✗"))
        lines.append(f"| {name} | {r['rate']:g} | {r['camera']} | {cell('speed', '{:.3f}')} | "
                     f"{cell('deviation', '{:.3f}')} | {cell('standing', '{:.2f}')} |")
    n = len(results)
    count = lambda c: ", ".join(f"{k} {c[k]}/{n}" for k in keys) + f", all three {c['all']}/{n}"  # noqa: E731
    lines += ["", f"The scene over seeds {', '.join(map(str, SEEDS))} pooled (in brackets, the range of the seeds alone). "
              f"Met pooled: {count(pooled)}. Met by seed {SEEDS[0]} alone: {count(first)}. Met by every seed alone: "
              f"{count(every)}."]
    return "\n".join(lines)


def crowd_table(results: dict) -> str:
    """Per sequence: how many people a frame and how long in view (median, seconds), real and the scene's pooled
    (no goal of issue 38's; what a tracker's associations meet)."""
    lines = ["| sequence | people a frame real / scene (ratio) | time in view real / scene, s (ratio) |",
             "|---|---:|---:|"]
    for name, r in results.items():
        real, scene = r["real"], r["pooled"]
        cells = [f"{real[k]:.1f} / {scene[k]:.1f} (x{scene[k] / real[k]:.2f})" for k in ("crowd", "time in view")]
        lines.append(f"| {name} | {cells[0]} | {cells[1]} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data", help="a folder of sequence folders (e.g. ../shared/data/mot15)")
    p.add_argument("--sensor", required=True, help="the detector's [sensor] table (mtt-sim calibrate)")
    p.add_argument("--only", nargs="*", help="only these sequences")
    args = p.parse_args(argv)
    folders = sorted(f for f in Path(args.data).iterdir() if (f / "det" / "det.txt").is_file()
                     and (not args.only or f.name in args.only))
    results = {}
    with tempfile.TemporaryDirectory(prefix="fit_scene_motion_") as scratch:
        for folder in folders:
            results[folder.name] = measure(folder, args.sensor, Path(scratch))
            print(f"{folder.name}: done", file=sys.stderr, flush=True)
    print(table(results))
    print()
    print(crowd_table(results))
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
