"""Issue 38's first goal, measured: does a label-free fitted scene move like the real sequence's people?

For every sequence folder under DATA (MOTChallenge layout: det/det.txt, gt/gt.txt, seqinfo.ini), `mtt-sim fit-scene`'s
fit (detections alone, detector from --sensor) is written as a scenario and run without a tracker at its own frame
rate (seeds 0 and 1); its scored truth and the sequence's ground truth are measured by one function
(`mtt_sim.sim2real.motion.people`): the median speed and one-second deviation (body heights) and the standing share.
The goal: the scene's speed and deviation within 0.67-1.5x of the real people's and its standing share within 0.1 of
theirs, on both seeds.

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

SEEDS = (0, 1)
RATIO = (0.67, 1.5)
STANDING_GAP = 0.1


def measure(folder: Path, sensor: str, scratch: Path) -> dict:
    frames, rate, _ = motion.scored_frames(str(folder))
    real = motion.people(frames, rate)
    raw = fit_scene.fit_scene(folder, sensor, seeds=())[0]
    path = scratch / f"{folder.name}.toml"
    path.write_text(scn.to_toml(raw, [f"fitted to {folder.name}"]))
    scene = []
    for seed in SEEDS:
        frames, scene_rate, _ = motion.scored_frames(str(path), seed=seed)
        scene.append(motion.people(frames, scene_rate))
    render, walk = raw.get("render", {}), raw.get("walk", {})
    return {"real": real, "scene": scene, "rate": raw.get("world", {}).get("frame_rate", 25.0),
            "camera": render.get("camera", "static"), "walk": walk.get("model", "off")}


def meets(real: dict, scene: dict) -> dict:
    ratio = lambda k: scene[k] / real[k] if real[k] > 0 else float("nan")  # noqa: E731
    return {"speed": RATIO[0] <= ratio("speed") <= RATIO[1], "deviation": RATIO[0] <= ratio("deviation") <= RATIO[1],
            "standing": abs(scene["standing"] - real["standing"]) <= STANDING_GAP}


def table(results: dict) -> str:
    lines = ["| sequence | fps (scene) | camera | speed real / scene (ratio) | deviation real / scene (ratio) | "
             "standing real / scene |", "|---|---:|---|---:|---:|---:|"]
    count = {"speed": 0, "deviation": 0, "standing": 0, "all": 0}
    for name, r in results.items():
        real, scene = r["real"], r["scene"]
        ok = [meets(real, s) for s in scene]
        both = {k: all(o[k] for o in ok) for k in ("speed", "deviation", "standing")}
        for k, v in both.items():
            count[k] += v
        count["all"] += all(both.values())
        mark = lambda k: "" if both[k] else " ✗"  # noqa: E731
        seeds = lambda k, f: "/".join(f.format(s[k]) for s in scene)  # noqa: E731
        ratios = lambda k: "/".join(f"{s[k] / real[k]:.2f}" for s in scene)  # noqa: E731
        lines.append(f"| {name} | {r['rate']:g} | {r['camera']} | {real['speed']:.3f} / {seeds('speed', '{:.3f}')} "
                     f"(x{ratios('speed')}){mark('speed')} | {real['deviation']:.3f} / {seeds('deviation', '{:.3f}')} "
                     f"(x{ratios('deviation')}){mark('deviation')} | {real['standing']:.2f} / "
                     f"{seeds('standing', '{:.2f}')}{mark('standing')} |")
    n = len(results)
    lines.append("")
    lines.append(f"Seeds {', '.join(map(str, SEEDS))} (values a seed each, separated by /); a goal is met when every "
                 f"seed meets it. Met: speed {count['speed']}/{n}, deviation {count['deviation']}/{n}, standing "
                 f"{count['standing']}/{n}, all three {count['all']}/{n}.")
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
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())
