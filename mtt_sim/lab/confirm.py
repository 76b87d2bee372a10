"""A tuned spec held against its defaults on seeds the study never saw.

A study's best is the best of many noisy trials on the same seeds, so its score there is biased upward (the winner's
curse): a spec can win by the luck of those seeds. The same spec and the defaults run on fresh seeds give a fair
comparison. Measured on the label-free scene route (docs/tuning.md): on four fresh seeds 11 of 48 tuned specs did not
beat their defaults, the route's worst loss on real video among them, and ranking the trackers by their fresh scores
instead of their studies' took the worst gap to the best tracker tuned on real labels from 11.9 to 4.6 HOTA.

Only simulated sources are run again: a recorded sequence replays the same episode whatever the seed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Mapping, Sequence

from mtt_sim.lab import routes
from mtt_sim.lab.experiment import run_tasks, score
from mtt_sim.metrics.goals import Goal


@dataclass(frozen=True)
class Confirmation:
    """The tuned `spec`'s and the `defaults`' scores on fresh `seeds` of the simulated `sources`: per goal, the mean
    over the episodes; `per_seed`, the first goal's per seed (the mean over the sources), tuned and defaults paired."""

    spec: str
    defaults: str
    seeds: tuple[int, ...]
    sources: tuple[str, ...]
    goals: tuple[Goal, ...]
    value: tuple[float, ...]
    default_value: tuple[float, ...]
    per_seed: tuple[float, ...]
    default_per_seed: tuple[float, ...]

    @property
    def holds(self) -> bool:
        """Whether the tuned spec beats the defaults in the first goal on the fresh seeds."""
        a, b = self.value[0], self.default_value[0]
        return a > b if self.goals[0].maximize else a < b

    def as_dict(self) -> dict:
        return {"spec": self.spec, "defaults": self.defaults, "seeds": list(self.seeds), "sources": list(self.sources),
                "value": list(self.value), "default_value": list(self.default_value), "holds": self.holds}

    def line(self) -> str:
        """One line for a report: both scores, and what to do where the tuned spec does not hold."""
        n, metric = len(self.seeds), self.goals[0].text
        text = f"on {n} fresh seed{'s' if n > 1 else ''} ({_seeds(self.seeds)}): {metric} {self.value[0]:.4g}"
        if self.spec == self.defaults:
            return text + " (the best is the defaults)"
        text += f", defaults {self.default_value[0]:.4g}"
        if not self.holds:
            text += (" - the tuned spec does not beat the defaults on seeds the study never saw: its gain was the "
                     "study's seeds' luck; keep the defaults, or tune on more seeds")
        return text


def fresh_seeds(seeds: Sequence[int], count: int) -> tuple[int, ...]:
    """`count` seeds after the largest of `seeds`: none of them a study on `seeds` ran."""
    start = max(seeds, default=-1) + 1
    return tuple(range(start, start + count))


def simulated(sources: Sequence[str], config: Mapping | None = None) -> list[str]:
    """The sources whose episodes a seed changes: every one but a sequence scored on its own detections."""
    return [s for s in sources if routes.route_of(s, config) is not None]


def confirm(spec: str, defaults: str, sources: Sequence[str], goals: Sequence[Goal], seeds: Sequence[int],
            config: Mapping | None = None, workers: int = 1, backend: str = "local",
            address: str | None = None) -> Confirmation | None:
    """`spec` and `defaults` on each simulated source of `sources` over `seeds` (fresh ones: `fresh_seeds`), the
    same worlds for both; None where no source is simulated. An episode that fails raises its error."""
    sources = simulated(sources, config)
    if not sources or not seeds:
        return None
    specs = (spec, defaults) if spec != defaults else (spec,)
    tasks = [(source, s, seed, dict(config or {}), None) for s in specs for source in sources for seed in seeds]
    records = run_tasks(tasks, workers, backend=backend, address=address)
    failed = [r["error"] for r in records if r["error"]]
    if failed:
        raise RuntimeError(f"confirming {spec}: {failed[0]}")
    block = len(sources) * len(seeds)
    tuned, base = records[:block], records[-block:]  # with one spec, the defaults are the spec itself

    def means(part: list[dict]) -> tuple[float, ...]:
        return tuple(math.fsum(score(r, g.metric) for r in part) / len(part) for g in goals)

    def per_seed(part: list[dict]) -> tuple[float, ...]:
        first = [score(r, goals[0].metric) for r in part]  # source-major: seed k of every source
        return tuple(math.fsum(first[k::len(seeds)]) / len(sources) for k in range(len(seeds)))

    return Confirmation(spec, defaults, tuple(seeds), tuple(sources), tuple(goals), means(tuned), means(base),
                        per_seed(tuned), per_seed(base))


def _seeds(seeds: Sequence[int]) -> str:
    """Seeds as a short text: 4-7, or 3, 5, 9."""
    if len(seeds) > 2 and list(seeds) == list(range(seeds[0], seeds[-1] + 1)):
        return f"{seeds[0]}-{seeds[-1]}"
    return ", ".join(map(str, seeds))
