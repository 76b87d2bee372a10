"""Stress search (falsification): an Optuna study over scenario keys for the scenes where a tracker does worst, or
loses most to another.

A candidate scene is the scenario with the searched keys set over the user's own overrides. It runs on each of
`seeds`, every tracker the objective names on the same world, and its value is the objective on its worst seed, so
the scene's TOML and that seed rerun it to the same value. The objective is arithmetic over metrics: a bare metric is
the searched tracker's, METRIC[spec] another's ("-MOTA", "IDSW", "MOTA[sort] - MOTA[lmb]"); the search makes it as
large as it can. Trials run one after another with a seeded sampler (TPE, CMA-ES or random), so one seed gives one
search whatever the number of workers. A trial whose episode raises is recorded as failed, with its error.
"""

from __future__ import annotations

import ast
import difflib
import math
import operator
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Sequence

from mtt_sim import trackers
from mtt_sim.lab.experiment import episode_pool, run_tasks
from mtt_sim.lab.journal import Journal
from mtt_sim.metrics import METRICS
from mtt_sim.sim import scenario as scenarios
from mtt_sim.core.settings import ConfigError

SAMPLERS = ("tpe", "cmaes", "random")


@dataclass(frozen=True)
class Dimension:
    """One searched key: numbers from low to high (integers for an integer key), or one of `choices`."""

    key: str
    kind: type
    low: float | None = None
    high: float | None = None
    choices: tuple = ()

    def suggest(self, trial):
        if self.choices:
            return trial.suggest_categorical(self.key, list(self.choices))
        if self.kind is int:
            return trial.suggest_int(self.key, int(self.low), int(self.high))
        return trial.suggest_float(self.key, self.low, self.high)

    def text(self) -> str:
        return f"{self.key}=" + ("|".join(map(str, self.choices)) if self.choices else f"{self.low:g}:{self.high:g}")


def dimension(text: str) -> Dimension:
    """KEY=LO:HI for a number, KEY=A|B|... for some of a key's choices, or KEY alone for all of them (true|false for
    a switch); checked against the key's own type, range and choices."""
    key, sep, values = (part.strip() for part in text.partition("="))
    kind, meta = scenarios.setting_of(key)
    allowed = (False, True) if kind is bool else tuple(meta.get("choices") or ())
    if kind in (int, float) and not allowed:
        low, colon, high = values.partition(":")
        try:
            low, high = kind(low), kind(high)
        except ValueError:
            raise ConfigError(f"{key}: expected {key}=LO:HI with {kind.__name__} bounds, got {text!r}") from None
        lo, hi = meta.get("lo"), meta.get("hi")
        if not colon or not low < high or (lo is not None and low < lo) or (hi is not None and high > hi):
            raise ConfigError(f"{key}={values}: expected LO:HI with LO < HI, within the key's range "
                              f"{'-inf' if lo is None else lo}..{'inf' if hi is None else hi}")
        return Dimension(key, kind, low, high)
    if not allowed:
        raise ConfigError(f"{key} is a {kind.__name__} without a list of choices: it cannot be searched")
    names = {str(c).lower(): c for c in allowed}
    picked = tuple(names.get(v.strip().lower(), v) for v in values.split("|")) if sep else allowed
    unknown = [v for v in picked if v not in allowed]
    if unknown:
        near = difflib.get_close_matches(str(unknown[0]).strip().lower(), names, n=1)
        raise ConfigError(f"{key}={values}: {str(unknown[0]).strip()!r} is not one of {key}'s choices"
                          + (f" (did you mean {names[near[0]]!r}?)" if near else "")
                          + f"; allowed: {'|'.join(map(str, allowed))}")
    if len(set(picked)) < 2:
        raise ConfigError(f"{key}={values}: expected two or more of {'|'.join(map(str, allowed))}")
    return Dimension(key, kind, choices=picked)


_TERM = re.compile(r"(?<![\w.])([A-Za-z_]\w*)(?:\[([^\]]*)\])?")
_OPERATORS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv}


class Objective:
    """What the search makes large: arithmetic (+ - * / and brackets) over metrics, METRIC for the searched tracker's,
    METRIC[spec] for another tracker's on the same world."""

    def __init__(self, text: str, spec: str):
        self.text = text
        self.terms: list[tuple[str, str]] = []  # (metric, tracker spec) of each placeholder _0, _1, ...
        names = {m.lower(): m for m in METRICS}

        def placeholder(match) -> str:
            metric = names.get(match.group(1).lower())
            if metric is None:
                near = difflib.get_close_matches(match.group(1).lower(), names, n=1)
                raise ValueError(f"objective {text!r}: unknown metric {match.group(1)!r}"
                                 + (f" (did you mean {names[near[0]]!r}?)" if near else "") + "; allowed: "
                                 + ", ".join(m for m in METRICS if m.isidentifier()))
            term = (metric, (match.group(2) or spec).strip())
            if term not in self.terms:
                self.terms.append(term)
            return f"_{self.terms.index(term)}"

        try:
            self.tree = ast.parse(_TERM.sub(placeholder, text).strip(), mode="eval")
            self.evaluate({f"_{i}": 1.0 for i in range(len(self.terms))})
        except (SyntaxError, ZeroDivisionError) as err:
            raise ValueError(f"objective {text!r}: {err}; expected arithmetic over metrics, e.g. -MOTA or "
                             "'MOTA[sort] - MOTA[lmb]'") from None
        if not self.terms:
            raise ValueError(f"objective {text!r} names no metric")
        self.specs = list(dict.fromkeys(s for _, s in self.terms))
        for s in self.specs:
            trackers.make(s)  # a bad spec fails here, before any episode

    def evaluate(self, values: Mapping[str, float], node=None) -> float:
        node = self.tree.body if node is None else node
        if isinstance(node, ast.Constant) and type(node.value) in (int, float):
            return float(node.value)
        if isinstance(node, ast.Name) and node.id in values:
            return values[node.id]
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            value = self.evaluate(values, node.operand)
            return -value if isinstance(node.op, ast.USub) else value
        if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
            return _OPERATORS[type(node.op)](self.evaluate(values, node.left), self.evaluate(values, node.right))
        raise SyntaxError(f"{ast.unparse(node)!r} is not allowed")

    def value(self, metrics: Mapping[str, Mapping]) -> float:
        """The objective of one world, from each tracker spec's episode summary."""
        values = {}
        for i, (metric, spec) in enumerate(self.terms):
            value = (metrics[spec] or {}).get(metric)
            if value is None:
                raise RuntimeError(f"{spec}: no {metric} (nothing to count in this scene)")
            values[f"_{i}"] = float(value)
        return self.evaluate(values)


@dataclass
class Scene:
    """One candidate scene: its searched values, its worst seed, the objective there, every tracker's metrics."""

    trial: int
    params: dict
    seed: int
    value: float
    metrics: dict


@dataclass
class Search:
    """A finished search: the scenes in trial order, and those whose episode raised (a crash is a finding too):
    their trial, searched values and error."""

    scenario: str
    config: dict
    sampler: str
    objective: Objective
    dimensions: list[Dimension]
    scenes: list[Scene] = field(default_factory=list)
    failed: list[dict] = field(default_factory=list)

    def worst(self, count: int) -> list[Scene]:
        """The `count` scenes of largest value, the earliest first among equals."""
        return sorted(self.scenes, key=lambda s: (-s.value, s.trial))[:count]

    def worst_so_far(self) -> list[float | None]:
        """The largest value after each evaluation (None until one succeeds)."""
        by_trial = {s.trial: s.value for s in self.scenes}
        best, out = -math.inf, []
        for t in range(len(self.scenes) + len(self.failed)):
            best = max(best, by_trial.get(t, -math.inf))
            out.append(best if best > -math.inf else None)
        return out

    def config_of(self, scene: Scene) -> dict:
        """Every override of the scene: the user's, then the searched ones."""
        return {**self.config, **scene.params}

    def toml(self, scene: Scene, comments: Sequence[str] = ()) -> str:
        """The scene as a complete scenario file, every key written out, so it needs nothing else to rerun."""
        loaded = scenarios.load(self.scenario, self.config_of(scene))
        return scenarios.to_toml(scenarios.to_mapping(loaded), comments)


def sampler(name: str, seed: int, budget: int):
    """The seeded Optuna sampler of `name`; TPE (multivariate: failures sit where keys meet) and CMA-ES start from a
    tenth of the budget (2 to 10 scenes) drawn at random."""
    import optuna

    startup = max(2, min(10, budget // 10))
    with warnings.catch_warnings():  # multivariate TPE is marked experimental
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        if name == "tpe":
            return optuna.samplers.TPESampler(seed=seed, multivariate=True, n_startup_trials=startup)
        if name == "cmaes":
            return optuna.samplers.CmaEsSampler(seed=seed, n_startup_trials=startup, warn_independent_sampling=False)
        if name == "random":
            return optuna.samplers.RandomSampler(seed=seed)
    raise ValueError(f"sampler {name!r}: allowed values: {', '.join(SAMPLERS)}")


def check_bounds(scenario: str, dimensions: Sequence[Dimension], config: Mapping) -> None:
    """Every bound of every dimension makes a valid scene with `config`, or the ConfigError says which does not."""
    for dim in dimensions:
        for value in (dim.choices or (dim.low, dim.high)):
            try:
                scenarios.load(scenario, {**config, dim.key: value})
            except ConfigError as err:
                raise ConfigError(f"{dim.key}={value} makes no valid scene: {err}") from None


def search(spec: str, scenario: str, dimensions: Sequence[Dimension], objective: str, budget: int,
           seeds: Sequence[int] = (0,), seed: int = 0, workers: int = 1, sampler_name: str = "tpe",
           config: Mapping | None = None, progress: bool = False, journal: Journal | None = None) -> Search:
    """Search `budget` scenes of `scenario` over `dimensions` for the largest `objective` of tracker `spec`. The
    episodes of each scene go into `journal`; a scene it holds is not run again but taken from it, so a search
    resumed from a journal replays the sampler's choices to the same scenes."""
    import optuna

    wanted = Objective(objective, spec)
    config = dict(config or {})
    check_bounds(scenario, dimensions, config)
    found = Search(scenario, config, sampler_name, wanted, list(dimensions))
    optuna.logging.set_verbosity(optuna.logging.ERROR)  # failed trials are kept and reported here
    study = optuna.create_study(direction="maximize", sampler=sampler(sampler_name, seed, budget))

    def evaluate(trial) -> float:
        params = {d.key: d.suggest(trial) for d in dimensions}
        tasks = [(scenario, s, k, {**config, **params}, None) for k in seeds for s in wanted.specs]
        records = run_tasks(tasks, workers, processes=processes, journal=journal)
        failed = next((r for r in records if r["error"]), None)
        if failed:
            raise RuntimeError(f"{failed['tracker']} seed {failed['seed']}: {failed['error']}")
        worlds = [{r["tracker"]: r["metrics"] for r in records[i:i + len(wanted.specs)]}
                  for i in range(0, len(records), len(wanted.specs))]
        values = [wanted.value(world) for world in worlds]
        worst = max(range(len(values)), key=lambda i: (values[i], -i))
        found.scenes.append(Scene(trial.number, params, seeds[worst], values[worst], worlds[worst]))
        return values[worst]

    def record_failure(study, trial) -> None:
        if trial.state == optuna.trial.TrialState.FAIL:
            found.failed.append({"trial": trial.number, "params": trial.params,
                                 "error": trial.user_attrs.get("error", "failed")})

    processes = episode_pool(workers) if workers > 1 else None
    try:
        study.optimize(lambda t: _keeping_error(evaluate, t), n_trials=budget, catch=(Exception,),
                       callbacks=[record_failure], show_progress_bar=progress)
    finally:
        if processes is not None:
            processes.close()
    return found


def _keeping_error(evaluate, trial) -> float:
    """evaluate(trial), with the error of a failed one kept on the trial."""
    try:
        return evaluate(trial)
    except Exception as err:
        trial.set_user_attr("error", f"{type(err).__name__}: {(str(err).splitlines() or [''])[0]}")
        raise


def table(found: Search, count: int) -> str:
    """The worst scenes as a Markdown table: rank, value, seed, the searched values and each tracker's main metrics."""
    keys = [d.key for d in found.dimensions]
    columns = ["rank", found.objective.text, "seed", *keys,
               *(f"{m}[{s}]" for s in found.objective.specs for m in ("MOTA", "IDF1", "HOTA", "IDSW"))]
    cell = lambda v: f"{v:.4g}" if isinstance(v, float) else str(v)  # noqa: E731
    rows = [[i + 1, s.value, s.seed, *(s.params[k] for k in keys),
             *((s.metrics[sp] or {}).get(m, "") for sp in found.objective.specs for m in ("MOTA", "IDF1", "HOTA", "IDSW"))]
            for i, s in enumerate(found.worst(count))]
    lines = [f"| {' | '.join(columns)} |", "|" + "---:|" * len(columns)]
    return "\n".join(lines + [f"| {' | '.join(map(cell, r))} |" for r in rows])


def history_plot(curves: Mapping[str, Sequence[float | None]], title: str, objective: str, path: str | Path) -> None:
    """Worst-so-far against scenes evaluated, one line per search (e.g. the sampler's and random sampling's)."""
    import textwrap

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    fig, ax = plt.subplots(figsize=(7, 4))
    for label, curve in curves.items():
        ax.plot(range(1, len(curve) + 1), [math.nan if v is None else v for v in curve], label=label,
                drawstyle="steps-post")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("scenes evaluated")
    ax.set_ylabel(f"worst so far: {objective}")
    ax.set_title(textwrap.fill(title, 90), fontsize=9)
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write(found: Search, out: str | Path, count: int, command: str = "", random: Search | None = None) -> list[dict]:
    """The `count` worst scenes into folder `out`, each rerun from its own file: worst-<rank>.toml (a complete
    scenario), .mp4 (every tracker of the objective side by side) and .jpg (the frame of the tracker's lowest step
    reward, or where the trackers' rewards differ most); then table.md and history.png (beside `random`'s, when given). Returns, worst first, each
    scene's file, seed, value and metrics as rerun; a rerun that does not give the search's value raises."""
    from mtt_sim.lab.experiment import run_episodes

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    specs = found.objective.specs
    written = []
    for rank, scene in enumerate(found.worst(count), 1):
        path = out / f"worst-{rank}.toml"
        again = f"mtt-sim run {path} --tracker '{specs[0]}' --seed {scene.seed}"
        path.write_text(found.toml(scene, [f"{found.objective.text} = {scene.value!r} on seed {scene.seed}: the "
                                           f"{_ordinal(rank)} worst of {len(found.scenes)} scenes searched",
                                           f"from: {command}" if command else f"from: {found.scenario}",
                                           ", ".join(f"{k} = {v!r}" for k, v in scene.params.items()),
                                           f"again: {again}"]))
        records = run_episodes(str(path), specs, scene.seed, video=str(path.with_suffix(".mp4")),
                               still=str(path.with_suffix(".jpg")))
        metrics = {r["tracker"]: r["metrics"] for r in records}
        value = found.objective.value(metrics)
        if value != scene.value:
            raise RuntimeError(f"{path} on seed {scene.seed} reran to {value!r}, not the search's {scene.value!r}")
        written.append({"scenario": str(path), "seed": scene.seed, "value": value, "params": scene.params,
                        "metrics": metrics if len(specs) > 1 else metrics[specs[0]]})
    (out / "table.md").write_text(table(found, count) + "\n")
    curves = {found.sampler: found.worst_so_far()}
    if random is not None:
        curves["random (same budget and seed)"] = random.worst_so_far()
    title = f"{found.scenario}: " + ", ".join(d.text() for d in found.dimensions)
    history_plot(curves, title, found.objective.text, out / "history.png")
    return written


def _ordinal(n: int) -> str:
    return {1: "1st", 2: "2nd", 3: "3rd"}.get(n, f"{n}th")
