"""What Ray adds to each episode of a sweep: the same grid of short episodes run in this process and as Ray tasks on
a local Ray instance of one CPU (started beforehand and warmed up, so neither its start nor the workers' imports
count). Needs the [ray] extra.

    python docs/experiments/ray_overhead.py [episodes] [steps]
"""

import statistics
import sys
import time

import ray

from mtt_sim.lab import experiment


def grid(episodes: int, steps: int, backend: str) -> float:
    start = time.perf_counter()
    records = experiment.run_grid(["sort"], ["crossing"], range(episodes), {"env.max_steps": steps}, backend=backend)
    assert not any(r["error"] for r in records)
    return time.perf_counter() - start


if __name__ == "__main__":
    episodes, steps = (int(a) for a in (sys.argv[1:] + ["200", "10"])[:2])
    started = time.perf_counter()
    ray.init(num_cpus=1, include_dashboard=False, log_to_driver=False, configure_logging=False)
    grid(4, steps, "ray")  # the worker's imports
    print(f"Ray start and first tasks: {time.perf_counter() - started:.1f} s")
    runs = [(grid(episodes, steps, "local"), grid(episodes, steps, "ray")) for _ in range(5)]
    local, remote = (statistics.median(r[i] for r in runs) for i in range(2))
    print(f"{episodes} episodes of {steps} steps, medians of 5: in process {local / episodes * 1e3:.1f} ms an episode, "
          f"as Ray tasks {remote / episodes * 1e3:.1f} ms: Ray adds {(remote - local) / episodes * 1e3:.1f} ms an episode")
    ray.shutdown()
