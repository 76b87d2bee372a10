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

import contextlib
import hashlib
import math
import tempfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm import tqdm

from mtt_sim.lab.experiment import episode_pool, run_tasks
from mtt_sim.lab.export import export_episode
from mtt_sim.lab.journal import Journal
from mtt_sim.real.layout import is_sequence
from mtt_sim.trackers.learned import save_policy
from mtt_sim.trackers.parts.management import SORT_RULES

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
            steps: int | None = None, journal: Journal | None = None, progress: bool = False) -> list[str]:
    """Each source and seed as a sequence folder under `folder`: a recorded sequence without a synthetic sensor as
    itself (once), anything else (a scenario, a twin) simulated once and exported (unless `journal` says it was)."""
    twin = dict(config or {}).get("sensor.model") == "synthetic"
    out, todo = [], []
    for i, source in enumerate(sources):
        if is_sequence(source) and not twin:
            out.append(str(source))
            continue
        for seed in seeds:
            target = folder / f"{i:02d}-{Path(str(source)).stem}-seed{seed}"
            out.append(str(target))
            todo.append((source, seed, target))
    for source, seed, target in tqdm(todo, desc="simulating the training episodes", unit="episode",
                                     disable=not progress or not todo):
        key = ("exported", target.name)
        if journal is None or key not in journal:
            export_episode(source, target, seed=seed, steps=steps, config=config, frames=False)
            if journal is not None:
                journal.put(key, True)
    return out


def learn_policy(sources: Sequence[str], seeds: Sequence[int] = (0,), generations: int = 20,
                 population: int | None = None, sigma: float = 1.0, seed: int = 0, workers: int = 1,
                 metrics: Sequence[str] = ("MOTA", "HOTA"), config: Mapping | None = None, steps: int | None = None,
                 progress: bool = False, base: str = "sort", work: str | Path | None = None,
                 journal: Journal | None = None) -> Learning:
    """CMA-ES over the policy's weights from SORT's rules, `generations` generations of `population` policies (None:
    CMA-ES's default for the dimension), on `sources` x `seeds` (with `config` overrides, cut to `steps` frames), the
    candidates proposed by `base`'s association. The training episodes and the policies' files go into folder `work`
    (None: a temporary one). With a `journal`, every replayed episode's score is kept in it, and what it holds is
    not replayed again: CMA-ES, seeded, asks for the same policies, so a resumed search ends where an uninterrupted
    one would (and one given more generations goes on from it)."""
    from cmaes import CMA

    if generations < 1:
        raise ValueError(f"generations={generations!r}: allowed: 1 or more")
    if population is not None and population < 4:
        raise ValueError(f"population={population!r}: allowed: 4 or more (CMA-ES's weights need several parents)")
    if not sigma > 0 or not math.isfinite(sigma):
        raise ValueError(f"sigma={sigma!r}: allowed: a finite number > 0")
    with contextlib.nullcontext(work) if work else tempfile.TemporaryDirectory(prefix="mtt-sim-learn-") as where:
        folder = Path(where).resolve()
        folder.mkdir(parents=True, exist_ok=True)
        episodes = replays(sources, seeds, folder, config, steps, journal, progress)
        start = SORT_RULES.ravel()
        optimizer = CMA(mean=start.copy(), sigma=sigma, seed=seed, population_size=population)
        processes = episode_pool(workers) if workers > 1 else None
        bar = tqdm(total=(1 + generations * optimizer.population_size) * len(episodes), unit="episode",
                   desc="SORT's rules", disable=not progress, dynamic_ncols=True)
        try:
            def fitness(weights: list[np.ndarray]) -> list[float]:
                keys = [[("score", _name(w), Path(e).name) for e in episodes] for w in weights]
                scores = {key: journal.get(key) for row in keys for key in row if journal is not None and key in journal}
                missing = {}  # (spec, episode) of each episode to replay: its key
                for w, row in zip(weights, keys):
                    path = folder / f"policy-{_name(w)}.npz"
                    if any(key not in scores for key in row):
                        save_policy(path, w.reshape(SORT_RULES.shape))
                    missing.update({(f"learned:policy={path},base={base}", e): key
                                    for e, key in zip(episodes, row) if key not in scores})
                bar.update(len(scores))

                def keep(record):
                    key = missing[record["tracker"], record["scenario"]]
                    scores[key] = _episode_score(record, metrics)
                    if journal is not None:
                        journal.put(key, scores[key])
                    bar.update()
                run_tasks([(e, spec, 0, {}, None) for spec, e in missing], workers, processes=processes,
                          on_record=keep)
                return [_fitness([scores[key] for key in row]) for row in keys]

            start_fitness = fitness([start])[0]
            learning = Learning(SORT_RULES.copy(), start_fitness, start_fitness, episodes=len(episodes))
            for g in range(generations):
                bar.set_description(f"generation {g + 1}/{generations}")
                xs = [optimizer.ask() for _ in range(optimizer.population_size)]
                values = fitness(xs)
                optimizer.tell([(x, -v if math.isfinite(v) else FAILED) for x, v in zip(xs, values)])
                best = int(np.argmax(values))
                if values[best] > learning.fitness:
                    learning.weights, learning.fitness = xs[best].reshape(SORT_RULES.shape), values[best]
                learning.best_so_far.append(learning.fitness)
                learning.generation_mean.append(float(np.mean(values)))
        finally:
            bar.close()
            if processes is not None:
                processes.close()
    return learning


def _name(weights: np.ndarray) -> str:
    """A policy's name in the work folder and the journal: a digest of its weights."""
    return hashlib.sha256(weights.tobytes()).hexdigest()[:16]


def _episode_score(record: dict, metrics: Sequence[str]) -> float:
    """The mean of `metrics` in one replayed episode; -inf if it failed."""
    if record["error"]:
        return -math.inf
    return math.fsum(record["metrics"][m] for m in metrics) / len(metrics)


def _fitness(scores: list[float]) -> float:
    """A policy's fitness: the mean of its episodes' scores; -inf if one failed (such a policy is never kept)."""
    return -math.inf if -math.inf in scores else math.fsum(scores) / len(scores)
