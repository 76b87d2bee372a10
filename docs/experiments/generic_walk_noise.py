"""Does a less predictable generic scene keep GM-PHD's `mot17_like`-tuned spec from failing on real video? Tune it on
`mot17_like` with the walkers' noise as shipped and tripled (20 trials, one seed each, sampler seed 0), and score each
tuned spec on every real sequence under DATA against the defaults (HOTA points).

    python docs/experiments/generic_walk_noise.py ../shared/data/mot15
"""

import json
import sys
from pathlib import Path

from mtt_sim.lab.experiment import run_episode
from mtt_sim.lab.tune import tune
from mtt_sim.sim2real import motion

NOISES = (0.079, 0.237)  # the shipped walk.noise, and three times it


def main() -> None:
    sequences = sorted(p for p in Path(sys.argv[1]).iterdir() if (p / "gt" / "gt.txt").is_file())
    defaults = {s.name: run_episode(str(s), "gmphd")["metrics"]["HOTA"] for s in sequences}
    for noise in NOISES:
        config = {"walk.noise": noise}
        frames, rate, _ = motion.scored_frames("mot17_like", config)
        result = tune("gmphd", ["mot17_like"], "HOTA", 20, range(1), config)[0]
        gains = {s.name: round(100 * (run_episode(str(s), result.spec)["metrics"]["HOTA"] - defaults[s.name]), 1)
                 for s in sequences}
        print(json.dumps({"walk.noise": noise, "deviation": round(motion.people(frames, rate)["deviation"], 3),
                          "tuned on mot17_like": round(result.value, 3), "spec": result.spec, "real gains": gains,
                          "mean": round(sum(gains.values()) / len(gains), 1)}))


if __name__ == "__main__":
    main()
