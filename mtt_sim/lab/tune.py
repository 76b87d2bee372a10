"""Tuning: an Optuna study over a tracker's search space, each trial scored by a metric's mean over sources and seeds.

A trial is the tracker's spec with the searched parameters set (those fixed in the spec stay fixed); its episodes run
source by source, each source's seeds in `workers` processes, and after each source the mean so far is reported, so a
hopeless trial is pruned on its first sources (single metric only: Optuna cannot prune a multi-objective study).
Trials run one after the other and TPE is seeded, so one seed gives one study, whatever the number of workers. The
first trial of a new study is the spec itself (its defaults): its score is the baseline a tuned spec is held against.
A trial whose episode raises is recorded as failed, with its error, and the study goes on.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Mapping, Sequence

from mtt_sim import trackers
from mtt_sim.lab.experiment import episode_pool, run_tasks
from mtt_sim.metrics.goals import Goal, goals
from mtt_sim.sim.scenario import to_toml
from mtt_sim.trackers.base import parse_spec, search_space, spec_of

@dataclass
class Result:
    """What a study found: the best spec (usable verbatim with --tracker and trackers.make), its score and the
    defaults' on the same sources and seeds, the trials by state, and the Pareto front of a multi-metric study."""

    spec: str
    value: float | list[float]
    default_value: float | list[float] | None
    params: dict
    trials: dict[str, int]
    goals: list[Goal]
    front: list[dict] = field(default_factory=list)

    def as_dict(self) -> dict:
        return {"spec": self.spec, "value": self.value, "default_value": self.default_value,
                "trials": sum(self.trials.values()), "states": self.trials, "params": self.params,
                "metric": ",".join(g.text for g in self.goals), "front": self.front}

    def toml(self) -> str:
        """The result as TOML: the spec, the scores and the parameters."""
        head = {k: v for k, v in self.as_dict().items() if k in ("spec", "metric", "trials")}
        scores = {k: v for k, v in (("value", self.value), ("default_value", self.default_value)) if v is not None}
        return to_toml({**head, **scores, "params": self.params})


def tune(spec: str, sources: Sequence[str], metric: str = "HOTA", trials: int = 50, seeds: Sequence[int] = (0,),
         config: Mapping | None = None, seed: int = 0, workers: int = 1, storage: str | None = None,
         study_name: str | None = None, time_budget: float | None = None, progress: bool = False,
         backend: str = "local", address: str | None = None) -> tuple[Result, object]:
    """Tune `spec` on `sources` (scenario keys, TOML files, sequence folders) over `seeds`: `trials` trials (or fewer
    within `time_budget` seconds), TPE seeded by `seed`; `storage` (an Optuna URL such as sqlite:///study.db) keeps
    the study, which a later call with the same `study_name` resumes. Returns the result and the Optuna study."""
    import optuna

    name, fixed = parse_spec(spec)
    tracker = trackers.make(spec)  # a bad spec fails here, before any episode
    space = search_space(name, fixed)
    if not space:
        raise ValueError(f"tracker {tracker.name!r} has no tunable parameter left to search (fixed in the spec: "
                         f"{', '.join(fixed) or 'none'})")
    wanted = goals(metric)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    study = optuna.create_study(
        storage=_storage(storage), study_name=study_name or f"{tracker.name} on {','.join(map(str, sources))}",
        load_if_exists=True, directions=["maximize" if g.maximize else "minimize" for g in wanted],
        sampler=optuna.samplers.TPESampler(seed=seed),
        pruner=optuna.pruners.MedianPruner(n_startup_trials=5) if len(wanted) == 1 else optuna.pruners.NopPruner())
    if not study.trials:
        study.enqueue_trial({k: tracker.params[k] for k in space}, user_attrs={"defaults": True})

    def objective(trial):
        params = {k: p.suggest(trial, k) for k, p in space.items()}
        trial_spec = spec_of(name, {**fixed, **params})
        trial.set_user_attr("spec", trial_spec)
        values = []
        for step, source in enumerate(sources):
            tasks = [(source, trial_spec, s, dict(config or {}), None) for s in seeds]
            records = run_tasks(tasks, workers, backend=backend, address=address, processes=processes)
            failed = [r["error"] for r in records if r["error"]]
            if failed:
                trial.set_user_attr("error", failed[0])
                raise RuntimeError(f"{trial_spec} on {source}: {failed[0]}")
            values += [[_score(r, g.metric) for g in wanted] for r in records]
            if len(wanted) == 1:
                trial.report(_mean(values, 0), step)
                if step < len(sources) - 1 and trial.should_prune():
                    raise optuna.TrialPruned()
        return tuple(_mean(values, k) for k in range(len(wanted)))

    remaining = max(0, trials - sum(t.state.is_finished() for t in study.trials))  # the enqueued defaults wait
    processes = episode_pool(workers) if workers > 1 and backend == "local" else None  # started once for every trial
    try:
        study.optimize(objective, n_trials=remaining, timeout=time_budget, catch=(Exception,),
                       show_progress_bar=progress)
    finally:
        if processes is not None:
            processes.close()
    return _result(study, name, fixed, wanted), study


def _storage(url: str | None):
    """The Optuna storage at `url` (None: in memory), or a ValueError naming the URL and what went wrong."""
    import optuna

    if url is None:
        return None
    try:
        return optuna.storages.get_storage(url)
    except Exception as err:  # noqa: BLE001  (SQLAlchemy's errors for a URL it cannot parse or open are many)
        raise ValueError(f"storage {url!r}: {str(err).splitlines()[0]} (e.g. sqlite:///study.db)") from None


def _score(record: dict, metric: str) -> float:
    value = (record["metrics"] or {}).get(metric)
    if value is None:
        raise RuntimeError(f"{record['scenario']}: no {metric} (an unscored source, or nothing to count)")
    return float(value)


def _mean(values: list[list[float]], k: int) -> float:
    return math.fsum(v[k] for v in values) / len(values)


def _result(study, name: str, fixed: Mapping, wanted: list[Goal]) -> Result:
    """The study's best trial (single metric), or the Pareto front's best in its first metric."""
    import optuna

    done = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    if not done:
        raise RuntimeError("no trial finished: " + "; ".join(sorted({t.user_attrs.get("error", t.state.name)
                                                                     for t in study.trials})))
    states = {s.name.lower(): sum(t.state == s for t in study.trials) for s in optuna.trial.TrialState
              if any(t.state == s for t in study.trials)}
    defaults = next((t for t in done if t.user_attrs.get("defaults")), None)
    front = study.best_trials if len(wanted) > 1 else [study.best_trial]
    first = wanted[0]
    best = (max if first.maximize else min)(front, key=lambda t: (t.values[0], -t.number))

    def scores(t):
        return t.values[0] if len(wanted) == 1 else list(t.values)

    return Result(spec=spec_of(name, {**fixed, **best.params}), value=scores(best),
                  default_value=scores(defaults) if defaults else None, params=dict(best.params), trials=states,
                  goals=wanted,
                  front=[{"spec": t.user_attrs["spec"], "value": scores(t)} for t in front] if len(wanted) > 1 else [])


def best_trials(study, wanted: list[Goal], count: int = 5) -> list[dict]:
    """The `count` best finished trials in the first metric: number, values and parameters."""
    import optuna

    done = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    done.sort(key=lambda t: (-t.values[0] if wanted[0].maximize else t.values[0], t.number))
    return [{"trial": t.number, **{g.text: v for g, v in zip(wanted, t.values)}, **t.params} for t in done[:count]]


def report(result: Result, study, count: int = 5) -> str:
    """The best trials as a Markdown table, then the best spec beside the defaults and the trials by state."""
    rows = best_trials(study, result.goals, count)
    columns = list(rows[0])
    cell = lambda v: f"{v:.4g}" if isinstance(v, float) else str(v)  # noqa: E731
    table = [f"| {' | '.join(columns)} |", "|" + "---:|" * len(columns)]
    table += [f"| {' | '.join(cell(r.get(c, '')) for c in columns)} |" for r in rows]
    metric = ",".join(g.text for g in result.goals)
    lines = ["", f"best: {result.spec}", f"{metric}: {result.value} (defaults: {result.default_value})",
             "trials: " + ", ".join(f"{n} {state}" for state, n in result.trials.items())]
    return "\n".join(table + lines)


def plot(study, wanted: list[Goal], path) -> None:
    """The optimisation history at `path` and the parameters' importances beside it (<stem>_importances.png), with
    Optuna's matplotlib plots; in a multi-metric study, of the first metric."""
    from pathlib import Path

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import optuna
    from optuna.visualization import matplotlib as views

    target = (lambda t: t.values[0]) if len(wanted) > 1 else None
    name = wanted[0].text
    path = Path(path)
    for draw, out in ((views.plot_optimization_history, path),
                      (views.plot_param_importances, path.with_name(f"{path.stem}_importances.png"))):
        with warnings.catch_warnings():  # Optuna marks its matplotlib plots experimental
            warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
            ax = draw(study, target=target, target_name=name)
        ax.figure.set_size_inches(7, 4)
        ax.figure.tight_layout()
        ax.figure.savefig(out, dpi=120)
        plt.close(ax.figure)
