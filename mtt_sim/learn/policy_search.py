"""Learn a track-management policy from the environment's score with CMA-ES (an evolution strategy: a
gradient-free reinforcement learner that needs only each policy's return).

The policy is `trackers.management`'s linear one: two weight rows over the candidates' features. Fitness is the mean
over the training episodes of the mean of `metrics` (e.g. MOTA and HOTA), each episode run by the `learned` tracker
with the candidate weights. The world does not depend on the agent's answers, so each training episode is simulated
once and written as a sequence folder (`export_episode`, without frames); every policy then replays those folders,
which costs only the tracker and the scoring. The search starts from SORT's own rules (`SORT_RULES`), so generation
0's fitness is SORT's and any gain is over SORT. One seed gives one policy, whatever the number of workers.
"""

from __future__ import annotations

import math
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from mtt_sim.lab.experiment import episode_pool, run_tasks
from mtt_sim.lab.export import export_episode
from mtt_sim.real.layout import is_sequence
from mtt_sim.trackers.learned import save_policy
from mtt_sim.trackers.management import SORT_RULES

FAILED = 1e9  # what CMA-ES minimises for a policy whose episode failed: worse than any score


@dataclass
class Learning:
    """The best policy found, its fitness, SORT's fitness (generation 0) and the curve: per generation the best
    fitness so far and the generation's mean."""

    weights: np.ndarray
    fitness: float
    start_fitness: float
    best_so_far: list[float] = field(default_factory=list)
    generation_mean: list[float] = field(default_factory=list)
    episodes: int = 0


def replays(sources: Sequence[str], seeds: Sequence[int], folder: Path, config: Mapping | None = None,
            steps: int | None = None) -> list[str]:
    """Each source and seed as a sequence folder under `folder`: a recorded sequence without a synthetic sensor as
    itself (once), anything else (a scenario, a twin) simulated once and exported."""
    out = []
    for i, source in enumerate(sources):
        twin = dict(config or {}).get("sensor.model") == "synthetic"
        if is_sequence(source) and not twin:
            out.append(str(source))
            continue
        for seed in seeds:
            target = folder / f"{i:02d}-{Path(str(source)).stem}-seed{seed}"
            export_episode(source, target, seed=seed, steps=steps, config=config, frames=False)
            out.append(str(target))
    return out


def learn_policy(sources: Sequence[str], seeds: Sequence[int] = (0,), generations: int = 20,
                 population: int | None = None, sigma: float = 1.0, seed: int = 0, workers: int = 1,
                 metrics: Sequence[str] = ("MOTA", "HOTA"), config: Mapping | None = None, steps: int | None = None,
                 progress: bool = False, base: str = "sort") -> Learning:
    """CMA-ES over the policy's weights from SORT's rules, `generations` generations of `population` policies (None:
    CMA-ES's default for the dimension), on `sources` x `seeds` (with `config` overrides, cut to `steps` frames), the
    candidates proposed by `base`'s association."""
    from cmaes import CMA

    if generations < 1:
        raise ValueError(f"generations={generations!r}: allowed: 1 or more")
    if population is not None and population < 4:
        raise ValueError(f"population={population!r}: allowed: 4 or more (CMA-ES's weights need several parents)")
    with tempfile.TemporaryDirectory(prefix="mtt-sim-learn-") as tmp:
        folder = Path(tmp)
        episodes = replays(sources, seeds, folder, config, steps)
        processes = episode_pool(workers) if workers > 1 else None
        try:
            def fitness(weights: list[np.ndarray]) -> list[float]:
                tasks = []
                for k, w in enumerate(weights):
                    save_policy(folder / f"policy{k}.npz", w.reshape(SORT_RULES.shape))
                    spec = f"learned:policy={folder / f'policy{k}.npz'},base={base}"
                    tasks += [(e, spec, 0, {}, None) for e in episodes]
                records = run_tasks(tasks, workers, processes=processes)
                return [_score(records[k * len(episodes):(k + 1) * len(episodes)], metrics) for k in range(len(weights))]

            start = SORT_RULES.ravel()
            start_fitness = fitness([start])[0]
            optimizer = CMA(mean=start.copy(), sigma=sigma, seed=seed, population_size=population)
            learning = Learning(SORT_RULES.copy(), start_fitness, start_fitness, episodes=len(episodes))
            for _ in tqdm(range(generations), desc="learning", unit="generation", disable=not progress):
                xs = [optimizer.ask() for _ in range(optimizer.population_size)]
                values = fitness(xs)
                optimizer.tell([(x, -v if math.isfinite(v) else FAILED) for x, v in zip(xs, values)])
                best = int(np.argmax(values))
                if values[best] > learning.fitness:
                    learning.weights, learning.fitness = xs[best].reshape(SORT_RULES.shape), values[best]
                learning.best_so_far.append(learning.fitness)
                learning.generation_mean.append(float(np.mean(values)))
        finally:
            if processes is not None:
                processes.close()
    return learning


def _score(records: list[dict], metrics: Sequence[str]) -> float:
    """The mean over episodes of the mean of `metrics`; -inf if an episode failed (such a policy is never kept)."""
    if any(r["error"] for r in records):
        return -math.inf
    return math.fsum(math.fsum(r["metrics"][m] for m in metrics) / len(metrics) for r in records) / len(records)
