"""What makes GM-PHD tuned on `mot17_like` fail on real video? Tune it on `mot17_like` as shipped, with the walkers'
noise tripled (people as unpredictable as ADL-Rundle-6's), and with --sensor's detector (e.g. the one `mtt-sim
calibrate` fits to the real sequences) in place of the MOT17 preset; 20 trials, one seed each, sampler seed 0. Each
tuned spec is scored on every real sequence under DATA against the defaults (HOTA points).

    python docs/experiments/generic_gmphd.py ../shared/data/mot15 --sensor fitted.toml
"""

import argparse
import json
import tomllib
from pathlib import Path

from mtt_sim.lab.experiment import run_episode
from mtt_sim.lab.tune import tune
from mtt_sim.sim2real import motion

TRIPLED = 0.237  # three times the shipped walk.noise (0.079)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("data", help="a folder of MOTChallenge sequence folders with gt/gt.txt")
    p.add_argument("--sensor", help="a sensor file ([sensor] table) for the third variant")
    args = p.parse_args()
    sequences = sorted(s for s in Path(args.data).iterdir() if (s / "gt" / "gt.txt").is_file())
    defaults = {s.name: run_episode(str(s), "gmphd")["metrics"]["HOTA"] for s in sequences}
    variants = {"as shipped": {}, "walk.noise tripled": {"walk.noise": TRIPLED}}
    if args.sensor:
        table = tomllib.loads(Path(args.sensor).read_text())["sensor"]
        variants[f"detector of {Path(args.sensor).name}"] = {f"sensor.{k}": v for k, v in table.items()}
    for name, config in variants.items():
        frames, rate, _ = motion.scored_frames("mot17_like", config)
        result = tune("gmphd", ["mot17_like"], "HOTA", 20, range(1), config)[0]
        gains = {s.name: round(100 * (run_episode(str(s), result.spec)["metrics"]["HOTA"] - defaults[s.name]), 1)
                 for s in sequences}
        print(json.dumps({"variant": name, "deviation": round(motion.people(frames, rate)["deviation"], 3),
                          "tuned on mot17_like": round(result.value, 3), "spec": result.spec, "real gains": gains,
                          "mean": round(sum(gains.values()) / len(gains), 1)}), flush=True)


if __name__ == "__main__":
    main()
