"""The label-free route in one step (`mtt-sim advise`): for a camera with detections and no labels, fit its scene
(`fit_scene`), tune each candidate tracker on it (`tune`) and rank them by the tuned spec's score on as many fresh
seeds of the scene (`confirm`: a study's best is flattered by its own seeds, and more so the noisier a tracker's
trials), with the simulator's confidence: each tuned spec's spread over those seeds and how often the first beats the
others seed by seed.

What the ranking is worth on real video is measured, not assumed: `routes.RECORD` holds the label-free route's figures
on the shared MOT15 sequences (docs/tuning.md), per kind of camera, and `warnings` adds the line a user of a camera of
that kind should read before trusting the ranking.
"""

from __future__ import annotations

import math
import statistics
from dataclasses import asdict, dataclass
from typing import Callable, Sequence

from mtt_sim.lab import routes

CANDIDATES = ("sort", "bytetrack", "ocsort", "iou", "gmphd")  # fast and sound on every shared sequence
FRAMES = 600  # about this many frames a trial, whatever the scene's length (`seeds_for`)
FRESH = 4  # the fewest fresh seeds a candidate is ranked on


@dataclass(frozen=True)
class Choice:
    """One candidate on the fitted scene: its tuned spec (for --tracker), its score a seed (fresh seeds of the scene,
    none of them tuned on), their mean and standard deviation, and the defaults' mean on the same seeds."""

    tracker: str
    spec: str
    per_seed: tuple[float, ...]
    default: float

    @property
    def score(self) -> float:
        return math.fsum(self.per_seed) / len(self.per_seed)

    @property
    def spread(self) -> float:
        return statistics.stdev(self.per_seed) if len(self.per_seed) > 1 else 0.0


def seeds_for(length: int, frames: int = FRAMES) -> list[int]:
    """The seeds of a study on a `length`-frame scene: as many as make about `frames` frames a trial, at least one.
    A short scene's trial is otherwise a few noisy frames: on the shared MOT15 sequences the label-free route's worst
    losses were the shortest sequences' studies, and went with about 600 frames a trial (docs/tuning.md)."""
    return list(range(max(1, round(frames / length))))


def fresh_count(seeds: Sequence[int]) -> int:
    """How many fresh seeds a candidate tuned on `seeds` is ranked on: as many, at least FRESH (one seed of a long
    scene would give no spread)."""
    return max(FRESH, len(seeds))


def advise(scene: str, candidates: Sequence[str] = CANDIDATES, metric: str = "HOTA", trials: int = 20,
           seeds: Sequence[int] = (0, 1, 2, 3), seed: int = 0, done: Callable[[str], Choice | None] | None = None,
           finished: Callable[[str, Choice], None] | None = None,
           say: Callable[[str], None] | None = None) -> list[Choice]:
    """Each candidate spec tuned on the scene file `scene` (`trials` trials of `seeds`, TPE seeded by `seed`), then
    run with its defaults on `fresh_count(seeds)` fresh seeds; best first on those. `done(spec)` gives a candidate
    finished earlier (a resumed run), `finished` is told each one as it finishes, `say` the progress."""
    from mtt_sim.lab import tune
    from mtt_sim.trackers import TrackerSpec

    say = say or (lambda line: None)
    choices = []
    for k, spec in enumerate(candidates, 1):
        choice = done(spec) if done else None
        if choice is None:
            say(f"advise: tuning {spec} ({k} of {len(candidates)}), {trials} trials x {len(seeds)} seeds")
            result, _ = tune.tune(spec, [scene], metric, trials, seeds, seed=seed, confirm_seeds=fresh_count(seeds))
            fresh = result.confirmed
            choice = Choice(TrackerSpec.of(spec).registered, result.spec, fresh.per_seed, fresh.default_value[0])
            if finished:
                finished(spec, choice)
        choices.append(choice)
    return sorted(choices, key=lambda c: -c.score)


def wins(first: Choice, other: Choice) -> int:
    """On how many of the fresh seeds `first` scores above `other` (paired: the same episodes)."""
    return sum(a > b for a, b in zip(first.per_seed, other.per_seed))


def table(choices: Sequence[Choice], metric: str) -> str:
    """The ranking as Markdown: rank, tracker, the tuned score (mean, sd over fresh seeds), the defaults', the seeds on
    which the first beats it, and the tuned spec."""
    lines = [f"| rank | tracker | {metric} tuned (mean ± sd over fresh seeds) | {metric} defaults | first wins on | "
             "tuned spec |", "|---:|---|---:|---:|---:|---|"]
    for rank, c in enumerate(choices, 1):
        beaten = "-" if rank == 1 else f"{wins(choices[0], c)} of {len(c.per_seed)} seeds"
        lines.append(f"| {rank} | {c.tracker} | {100 * c.score:.1f} ± {100 * c.spread:.1f} | {100 * c.default:.1f} | "
                     f"{beaten} | `{c.spec}` |")
    return "\n".join(lines)


def warnings(choices: Sequence[Choice], camera: str) -> list[str]:
    """What a user should know before trusting the ranking: a first choice within the seeds' spread of the second
    (the simulator cannot tell them apart), a first choice whose tuned spec scores below its defaults on the fresh
    seeds, and the route's record for the first choice's tracker on real cameras of this kind (`camera`, as
    `routes.camera_kind` reads it; `routes.RECORD`)."""
    out = []
    if len(choices) > 1:
        a, b = choices[0], choices[1]
        if a.score - b.score <= max(a.spread, b.spread) or wins(a, b) < len(a.per_seed):
            out.append(f"{a.tracker} and {b.tracker} are within the seeds' spread on this scene ({wins(a, b)} of "
                       f"{len(a.per_seed)} seeds to {a.tracker}): the scene cannot tell them apart; try both")
    if choices and choices[0].score < choices[0].default:
        first = choices[0]
        out.append(f"{first.tracker}'s tuned spec scores below its defaults on the fresh seeds "
                   f"({100 * first.score:.1f} against {100 * first.default:.1f}): its study's gain did not hold; "
                   "its defaults may do better")
    line = routes.caution("scene", camera, choices[0].tracker if choices else routes.ANY)
    if line:
        out.append(line)
    return out


def as_dict(choice: Choice) -> dict:
    """A choice as plain values, with its mean and spread."""
    return {**asdict(choice), "per_seed": list(choice.per_seed), "score": choice.score, "spread": choice.spread}
