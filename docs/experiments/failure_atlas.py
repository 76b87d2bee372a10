"""The failure atlas of docs/failure_atlas.md: `mtt-sim stress` for sort, bytetrack, lmb and jpda on mot17_like and
crossing, where sort beats lmb and bytetrack and where they beat it, and where camera-motion compensation gains and
loses most, `--jobs` searches at a time; each search's worst scenes (TOML, still, video), table and history into
OUT/<search>/, and OUT/summary.json.

    python docs/experiments/failure_atlas.py --out docs/atlas --budget 20 --jobs 2
"""

import argparse
import json
import shlex
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

SCENES = {  # what each scenario's search varies, and the fixed overrides (a shaking camera whose shake is searched)
    "mot17_like": ("groups.0.count=4:30,groups.0.speed=0.8:3.2,sensor.clutter_rate=0:6,sensor.pd=0.5:0.95,"
                   "render.shake=0:10", ["render.camera=shake", "env.max_steps=300"]),
    "crossing": ("groups.0.speed=0.5:3,groups.1.speed=0.5:3,render.noise=0:25,render.brightness=0.3:1.2,"
                 "render.shake=0:6", ["render.camera=shake"]),
}
TRACKERS = ("sort", "bytetrack", "lmb", "jpda")
PAIRS = (("sort", "lmb"), ("sort", "bytetrack"), ("sort", "sort:cmc=sparse_flow"))


def searches() -> dict[str, tuple[str, str, str]]:
    """name -> (tracker, scenario, objective): each tracker's worst MOTA on each scenario, then both ways of each
    pair on mot17_like (A-beats-B: the scenes where B loses most MOTA to A)."""
    out = {f"{t}-{s}": (t, s, "-MOTA") for s in SCENES for t in TRACKERS}
    for a, b in PAIRS:
        name_a, name_b = (n.replace(":", "-").replace("=", "-") for n in (a, b))
        out[f"{name_a}-beats-{name_b}"] = (a, "mot17_like", f"MOTA[{a}] - MOTA[{b}]")
        out[f"{name_b}-beats-{name_a}"] = (a, "mot17_like", f"MOTA[{b}] - MOTA[{a}]")
    return out


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="docs/atlas")
    p.add_argument("--budget", type=int, default=20)
    p.add_argument("--top", type=int, default=2)
    p.add_argument("--jobs", type=int, default=2, help="searches at a time (one process each)")
    args = p.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    def run(item):
        name, (tracker, scenario, objective) = item
        vary, config = SCENES[scenario]
        command = ["mtt-sim", "stress", tracker, "--scenario", scenario, "--vary", vary, f"--objective={objective}",
                   "--budget", str(args.budget), "--top", str(args.top), "--out", str(out / name), "--force",
                   "--json", "--config", *config]
        start = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode:
            sys.exit(f"{shlex.join(command)} failed:\n{done.stderr}")
        print(f"{name}: {time.perf_counter() - start:.0f} s", flush=True)
        return name, {"command": shlex.join(command), **json.loads(done.stdout)}

    start = time.perf_counter()
    with ThreadPoolExecutor(args.jobs) as pool:
        summary = dict(pool.map(run, searches().items()))
    (out / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    print(f"atlas: {len(summary)} searches of {args.budget} scenes in {(time.perf_counter() - start) / 60:.1f} min "
          f"({args.jobs} at a time); {out}/summary.json")
    for name, result in summary.items():
        worst = result["worst"][0]
        print(f"  {name}: {worst['value']:.3f} on seed {worst['seed']}: "
              + ", ".join(f"{k.split('.', 1)[1]}={v:.3g}" if isinstance(v, float) else f"{k}={v}"
                          for k, v in worst["params"].items()))


if __name__ == "__main__":
    main()
