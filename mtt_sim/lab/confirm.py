"""A study's best trials and its defaults run again on seeds the study never saw, the best of them there kept.

A study's best is the best of many noisy trials on the same seeds, so its score there is biased upward (the winner's
curse): a spec can win by the luck of those seeds. Its few best trials (CONTENDERS) and the defaults run on fresh
seeds give a fair comparison, and the contender that scores best there is the one kept. Measured on the label-free
scene route (docs/tuning.md, "Fresh seeds"): 11 of 48 studies' best did not beat their defaults on four fresh seeds,
the route's worst loss on real video among them, and ranking the trackers by their fresh scores instead of their
studies' took the worst gap to the best tracker tuned on real labels from 11.9 to 4.6 HOTA.

Only simulated sources are run again: a recorded sequence replays the same episode whatever the seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Sequence

from mtt_sim.lab import routes
from mtt_sim.lab.experiment import run_tasks, score
from mtt_sim.metrics.goals import Goal

CONTENDERS = 3  # a study's best trials run again


@dataclass(frozen=True)
class Confirmation:
    """The `contenders` (a study's best specs, its best first) and the `defaults` on fresh `seeds` of the simulated
    `sources`: per spec and goal, the mean over the episodes (`values`, `default_value`); `per_seed`, the first goal's
    per seed (the mean over the sources) of the kept contender and of the defaults, paired."""

    contenders: tuple[str, ...]
    defaults: str
    seeds: tuple[int, ...]
    sources: tuple[str, ...]
    goals: tuple[Goal, ...]
    values: tuple[tuple[float, ...], ...]
    default_value: tuple[float, ...]
    per_seed: tuple[float, ...]
    default_per_seed: tuple[float, ...]

    @property
    def kept(self) -> int:
        """The contender with the best first goal on the fresh seeds (the earlier on a tie)."""
        return _kept(self.values, self.goals[0])

    @property
    def spec(self) -> str:
        return self.contenders[self.kept]

    @property
    def value(self) -> tuple[float, ...]:
        return self.values[self.kept]

    @property
    def holds(self) -> bool:
        """Whether the kept spec beats the defaults in the first goal on the fresh seeds."""
        a, b = self.value[0], self.default_value[0]
        return a > b if self.goals[0].maximize else a < b

    def as_dict(self) -> dict:
        return {"spec": self.spec, "contenders": list(self.contenders), "defaults": self.defaults,
                "seeds": list(self.seeds), "sources": list(self.sources), "values": [list(v) for v in self.values],
                "value": list(self.value), "default_value": list(self.default_value), "holds": self.holds}

    def lines(self) -> list[str]:
        """For a report: each contender's score beside the defaults', the one kept, and what to do where it does not
        beat the defaults."""
        n, metric = len(self.seeds), self.goals[0].text
        out = [f"on {n} fresh seed{'s' if n > 1 else ''} ({_seeds(self.seeds)}), {metric}: defaults "
               f"{self.default_value[0]:.4g}"]
        for i, (spec, v) in enumerate(zip(self.contenders, self.values)):
            mark = "kept " if i == self.kept else "     "
            out.append(f"  {mark}{v[0]:.4g}  {spec}" + (" (the defaults)" if spec == self.defaults else ""))
        if not self.holds and self.spec != self.defaults:
            out.append("the kept spec does not beat the defaults on seeds the study never saw: the study's gain was "
                       "its seeds' luck; keep the defaults, or tune on more seeds")
        return out


def fresh_seeds(seeds: Sequence[int], count: int) -> tuple[int, ...]:
    """`count` seeds after the largest of `seeds`: none of them a study on `seeds` ran."""
    start = max(seeds, default=-1) + 1
    return tuple(range(start, start + count))


def simulated(sources: Sequence[str], config: Mapping | None = None) -> list[str]:
    """The sources whose episodes a seed changes: every one but a sequence scored on its own detections."""
    return [s for s in sources if routes.route_of(s, config) is not None]


def confirm(contenders: Sequence[str], defaults: str, sources: Sequence[str], goals: Sequence[Goal],
            seeds: Sequence[int], config: Mapping | None = None, workers: int = 1, backend: str = "local",
            address: str | None = None) -> Confirmation | None:
    """Each of `contenders` and `defaults` on each simulated source of `sources` over `seeds` (fresh ones:
    `fresh_seeds`), the same worlds for all; None where no source is simulated. A failed episode raises its error."""
    sources = simulated(sources, config)
    if not sources or not seeds:
        return None
    specs = list(dict.fromkeys([*contenders, defaults]))  # each run once, the defaults among the contenders or not
    tasks = [(source, s, seed, dict(config or {}), None) for s in specs for source in sources for seed in seeds]
    records = run_tasks(tasks, workers, backend=backend, address=address)
    failed = [r["error"] for r in records if r["error"]]
    if failed:
        raise RuntimeError(f"confirming {contenders[0]}: {failed[0]}")
    block = len(sources) * len(seeds)
    runs = {s: records[k * block:(k + 1) * block] for k, s in enumerate(specs)}

    def means(part: list[dict]) -> tuple[float, ...]:
        return tuple(math.fsum(score(r, g.metric) for r in part) / len(part) for g in goals)

    def per_seed(part: list[dict]) -> tuple[float, ...]:
        first = [score(r, goals[0].metric) for r in part]  # source-major: seed k of every source
        return tuple(math.fsum(first[k::len(seeds)]) / len(sources) for k in range(len(seeds)))

    values = tuple(means(runs[s]) for s in contenders)
    return Confirmation(tuple(contenders), defaults, tuple(seeds), tuple(sources), tuple(goals), values,
                        means(runs[defaults]), per_seed(runs[contenders[_kept(values, goals[0])]]),
                        per_seed(runs[defaults]))


def _kept(values: Sequence[Sequence[float]], goal: Goal) -> int:
    """The index of the best of `values` in their first goal, `goal` (the earlier on a tie)."""
    sign = 1 if goal.maximize else -1
    return max(range(len(values)), key=lambda i: (sign * values[i][0], -i))


def _seeds(seeds: Sequence[int]) -> str:
    """Seeds as a short text: 4-7, or 3, 5, 9."""
    if len(seeds) > 2 and list(seeds) == list(range(seeds[0], seeds[-1] + 1)):
        return f"{seeds[0]}-{seeds[-1]}"
    return ", ".join(map(str, seeds))
