"""Tuning: an Optuna study over a tracker's search space, each trial scored by a metric's mean over sources and seeds.

A trial is the tracker's spec with the searched parameters set (those fixed in the spec stay fixed); its episodes run
source by source, each source's seeds in `workers` processes, and after each source the mean so far is reported, so a
hopeless trial is pruned on its first sources (single metric only: Optuna cannot prune a multi-objective study).
Trials run one after the other, each drawn by TPE seeded from the study's seed and the number of trials finished
before it, so one seed gives one study, whatever the number of workers, and a resumed study draws what an
uninterrupted one would have. The first trial of a new study is the spec itself (its defaults): its score is the
baseline a tuned spec is held against. A trial whose episode raises is recorded as failed, with its error, and the
study goes on.

The study itself, what defines it and whether a stored one may be resumed, is `mtt_sim.lab.study`'s; here it is
run. Ctrl-C (or SIGTERM, which the command maps to it) marks the trial in flight as interrupted, which does not count
towards `trials` and is rerun first on resume; storage writes are never cut in half.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import socket
import threading
import time
import warnings
from dataclasses import dataclass, field
from typing import Callable, Mapping, Sequence

from mtt_sim.lab.confirm import CONTENDERS, Confirmation, confirm, fresh_seeds
from mtt_sim.lab.experiment import episode_pool, run_tasks, score
from mtt_sim.lab.study import (counted, default_study_name, definition, mark_interrupted, open_storage, open_study,
                               state)
from mtt_sim.metrics.goals import Goal, goals
from mtt_sim.sim.scenario import to_toml
from mtt_sim.trackers.base import TrackerSpec, search_space, spec_of


@dataclass
class Result:
    """What a study found: the best spec (usable verbatim with --tracker and trackers.make), its score and the
    defaults' on the same sources and seeds, the trials by state, and the Pareto front of a multi-metric study; the
    study's name, its finished trials (complete, pruned or failed by their own error) against the number wanted,
    those kept from an earlier run, and whether this run was interrupted (the best so far, then)."""

    spec: str
    value: float | list[float]
    default_value: float | list[float] | None
    params: dict
    trials: dict[str, int]
    goals: list[Goal]
    front: list[dict] = field(default_factory=list)
    study: str = ""
    finished: int = 0
    wanted: int = 0
    kept: int = 0
    interrupted: bool = False
    confirmed: Confirmation | None = None

    def as_dict(self) -> dict:
        return {"spec": self.spec, "value": self.value, "default_value": self.default_value,
                "trials": self.finished, "trials_wanted": self.wanted, "interrupted": self.interrupted,
                "study": self.study, "states": self.trials, "params": self.params,
                "metric": ",".join(g.text for g in self.goals), "front": self.front,
                "confirmed": self.confirmed.as_dict() if self.confirmed else None}

    def toml(self) -> str:
        """The result as TOML: the spec, the study, the trials finished (of those wanted, and whether interrupted),
        the scores and the parameters."""
        head = {k: v for k, v in self.as_dict().items()
                if k in ("spec", "metric", "study", "trials", "trials_wanted", "interrupted")}
        scores = {k: v for k, v in (("value", self.value), ("default_value", self.default_value)) if v is not None}
        confirmed = {"confirmed": self.confirmed.as_dict()} if self.confirmed else {}
        return to_toml({**head, **scores, "params": self.params, **confirmed})


class NoTrialFinished(RuntimeError):
    """A study in which no trial completed: each failed by its own error, was pruned or interrupted. The message, one
    line, names why: the trials' distinct errors (each's first line), or their states."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during a study: the trial in flight marked interrupted, `result` the best so far (None if no trial had
    finished) and `study` the Optuna study. A KeyboardInterrupt, so a caller that does not look stops as before."""

    def __init__(self, result: Result | None, study):
        super().__init__("tuning interrupted")
        self.result, self.study = result, study


def tune(spec: str, sources: Sequence[str], metric: str = "HOTA", trials: int = 50, seeds: Sequence[int] = (0,),
         config: Mapping | None = None, seed: int = 0, workers: int = 1, storage: str | None = None,
         study_name: str | None = None, time_budget: float | None = None, progress: bool = False,
         backend: str = "local", address: str | None = None, confirm_seeds: int = 0,
         say: Callable[[str], None] | None = None) -> tuple[Result, object]:
    """Tune `spec` on `sources` (scenario keys, TOML files, sequence folders) over `seeds` until the study has
    `trials` finished trials (complete, pruned, or failed by their own error; fewer within `time_budget` seconds),
    TPE seeded by `seed`. `storage` (an Optuna URL such as sqlite:///study.db) keeps the study, which a later call
    resumes: by default it is named after the definition, and a `study_name` whose stored definition differs is
    refused with a ValueError. With `confirm_seeds`, the study's best trials and the defaults then run on that many
    fresh seeds of the simulated sources, and the best of those trials there is the result (`confirm`; the result's
    `confirmed`). `say` gets the lines worth telling a user (a
    resumed study's counts, a failed trial).
    Returns the result and the Optuna study; on Ctrl-C raises `Interrupted` with the best so far."""
    import optuna

    spec = TrackerSpec.of(spec)  # a bad spec fails here, before any episode; parsed once for the whole study
    name, fixed = spec.name, spec.params
    space = search_space(name, fixed)
    if not space:
        raise ValueError(f"tracker {spec.registered!r} has no tunable parameter left to search (fixed in the spec: "
                         f"{', '.join(fixed) or 'none'})")
    wanted = goals(metric)
    defined, digest = definition(spec, sources, metric, seeds, config)
    own_name = default_study_name(spec, sources, metric, digest)
    say = say or (lambda line: None)
    optuna.logging.set_verbosity(optuna.logging.WARNING)
    store = open_storage(storage)
    interrupts = _Interrupts()
    with interrupts.held():
        study, kept = open_study(store, study_name or own_name, own_name, defined, digest, wanted, trials,
                                 {k: spec.values[k] for k in space}, say, _sampler(0, 0))

        def objective(trial):
            params = {k: p.suggest(trial, k) for k, p in space.items()}
            trial_spec = spec_of(name, {**fixed, **params})
            trial.set_user_attr("spec", trial_spec)
            values = []
            for step, source in enumerate(sources):
                tasks = [(source, trial_spec, s, dict(config or {}), None) for s in seeds]
                with interrupts.allowed():  # the episodes: the one place Ctrl-C stops at once
                    records = run_tasks(tasks, workers, backend=backend, address=address, processes=processes,
                                        parsed=sources)  # a SourceSpec (the command line's) read once a study
                failed = [r["error"] for r in records if r["error"]]
                if failed:
                    trial.set_user_attr("error", failed[0])
                    raise RuntimeError(f"{trial_spec} on {source}: {failed[0]}")
                values += [[score(r, g.metric) for g in wanted] for r in records]
                if len(wanted) == 1:
                    trial.report(_mean(values, 0), step)
                    if step < len(sources) - 1 and trial.should_prune():
                        raise optuna.TrialPruned()
            return [_mean(values, k) for k in range(len(wanted))]

        started, trial, interrupted = time.monotonic(), None, False
        finished = len(counted(study.trials))
        processes = episode_pool(workers) if workers > 1 and backend == "local" and finished < trials else None
        bar = _bar(trials, finished, progress)
        try:
            while finished < trials and (time_budget is None or time.monotonic() - started < time_budget):
                interrupts.check()
                study.sampler = _sampler(seed, finished)  # trial k's draws follow from seed and k alone
                trial = study.ask()
                trial.set_user_attr("runner", {"host": socket.gethostname(), "pid": os.getpid()})
                try:
                    values = objective(trial)
                except optuna.TrialPruned:
                    study.tell(trial, state=optuna.trial.TrialState.PRUNED)
                except Exception as err:  # noqa: BLE001  (a trial's own error fails that trial; the study goes on)
                    message = trial.user_attrs.get("error") or f"{type(err).__name__}: {err}"
                    trial.set_user_attr("error", message)
                    study.tell(trial, state=optuna.trial.TrialState.FAIL)
                    with bar.external_write_mode():
                        say(f"trial {trial.number} failed: {message.splitlines()[0] if message else ''}")
                else:
                    bad = [g.metric for g, v in zip(wanted, values) if not math.isfinite(v)]
                    if bad:
                        trial.set_user_attr("error", f"{', '.join(bad)} is not a number")
                        study.tell(trial, state=optuna.trial.TrialState.FAIL)
                    else:
                        study.tell(trial, values)
                trial = None
                finished = len(counted(study.trials))
                bar.update(finished - bar.n)
        except KeyboardInterrupt:
            interrupted = True
            if trial is not None:
                mark_interrupted(study, trial)
        finally:
            bar.close()
            if processes is not None:
                processes.close(wait=not interrupted)
        if interrupted:
            try:
                result = _result(study, name, fixed, wanted)
            except NoTrialFinished:  # no trial has finished yet
                result = None
            else:
                result.interrupted = True
            _note(result, study, trials, kept)
            raise Interrupted(result, study)
        result = _result(study, name, fixed, wanted)
    if confirm_seeds:  # after the study, so Ctrl-C stops it at once; the study itself is finished and stored
        defaults = spec_of(name, {**fixed, **{k: spec.values[k] for k in space}})
        contenders = contenders_of(study, result, wanted)
        try:
            result.confirmed = confirm([t.user_attrs["spec"] for t in contenders], defaults, sources, wanted,
                                       fresh_seeds(seeds, confirm_seeds), config, workers, backend, address)
            if result.confirmed:
                chosen = contenders[result.confirmed.kept]
                result.spec, result.params = chosen.user_attrs["spec"], dict(chosen.params)
                result.value = chosen.values[0] if len(wanted) == 1 else list(chosen.values)
        except KeyboardInterrupt:
            result.interrupted = True
            _note(result, study, trials, kept)
            raise Interrupted(result, study) from None
    _note(result, study, trials, kept)
    return result, study


def _sampler(seed: int, index: int):
    """TPE for the trial drawn after `index` counted trials, seeded from the study's seed and `index` alone: a
    resumed study draws what an uninterrupted one would have (the sampler's own random state is not stored)."""
    import numpy as np
    import optuna

    return optuna.samplers.TPESampler(seed=int(np.random.SeedSequence([seed, index]).generate_state(1)[0]))


class _Interrupts:
    """Ctrl-C, and SIGTERM where a handler turns it into KeyboardInterrupt, held back while the study's storage is
    written: inside `allowed` (the episodes) it stops at once; elsewhere it waits for the next `check` or `allowed`."""

    def __init__(self):
        self.pending = self.open = False

    def _handler(self, signum, frame):
        if self.open:
            raise KeyboardInterrupt
        self.pending = True

    @contextlib.contextmanager
    def held(self):
        previous = {}
        if threading.current_thread() is threading.main_thread():  # a handler can only be set there
            for sig in (signal.SIGINT, signal.SIGTERM):
                if callable(signal.getsignal(sig)):  # not where it is ignored or left to kill the process
                    previous[sig] = signal.signal(sig, self._handler)
        try:
            yield self
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)

    def check(self) -> None:
        if self.pending:
            self.pending = False
            raise KeyboardInterrupt

    @contextlib.contextmanager
    def allowed(self):
        self.check()
        self.open = True
        try:
            yield
        finally:
            self.open = False


def _bar(trials: int, finished: int, progress: bool):
    from tqdm import tqdm

    return tqdm(total=trials, initial=min(finished, trials), unit="trial", disable=not progress, dynamic_ncols=True)


def _note(result: Result | None, study, trials: int, kept: int) -> None:
    if result is not None:
        result.study, result.finished, result.wanted, result.kept = (study.study_name, len(counted(study.trials)),
                                                                     trials, kept)


def _mean(values: list[list[float]], k: int) -> float:
    return math.fsum(v[k] for v in values) / len(values)


def _result(study, name: str, fixed: Mapping, wanted: list[Goal]) -> Result:
    """The study's best trial (single metric), or the Pareto front's best in its first metric."""
    import optuna

    done = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    if not done:
        why = sorted({(t.user_attrs.get("error") or "").partition("\n")[0] or state(t) for t in study.trials})
        raise NoTrialFinished("no trial finished: " + "; ".join(why))
    counts = {}
    for t in study.trials:
        counts[state(t)] = counts.get(state(t), 0) + 1
    states = {s: counts[s] for s in ("complete", "pruned", "fail", "interrupted", "running", "waiting") if s in counts}
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


def contenders_of(study, result: Result, wanted: list[Goal]) -> list:
    """The study's best trial (the result's) and the next best in the first metric: CONTENDERS in all, each spec
    once."""
    import optuna

    done = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    done.sort(key=lambda t: (-t.values[0] if wanted[0].maximize else t.values[0], t.number))
    best = next(t for t in done if t.user_attrs["spec"] == result.spec)
    out = {best.user_attrs["spec"]: best}
    for t in done:
        if len(out) == CONTENDERS:
            break
        out.setdefault(t.user_attrs["spec"], t)
    return list(out.values())


def best_trials(study, wanted: list[Goal], count: int = 5) -> list[dict]:
    """The `count` best finished trials in the first metric: number, values and parameters."""
    import optuna

    done = [t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE]
    done.sort(key=lambda t: (-t.values[0] if wanted[0].maximize else t.values[0], t.number))
    return [{"trial": t.number, **{g.text: v for g, v in zip(wanted, t.values)}, **t.params} for t in done[:count]]


def report(result: Result, study, count: int = 5) -> str:
    """The best trials as a Markdown table, then the study, the best spec beside the defaults and the trials by
    state; an interrupted run's best is the best so far, and says so."""
    rows = best_trials(study, result.goals, count)
    columns = list(rows[0])
    cell = lambda v: f"{v:.4g}" if isinstance(v, float) else str(v)  # noqa: E731
    table = [f"| {' | '.join(columns)} |", "|" + "---:|" * len(columns)]
    table += [f"| {' | '.join(cell(r.get(c, '')) for c in columns)} |" for r in rows]
    metric = ",".join(g.text for g in result.goals)
    lines = ["", *([f"study: {result.study}"] if result.study else []),
             f"{_label(result)}: {result.spec}",
             f"{metric}: {result.value} (defaults: {result.default_value}){' on the study' * bool(result.confirmed)}",
             "trials: " + ", ".join(f"{n} {state}" for state, n in result.trials.items())]
    if result.confirmed:
        lines += result.confirmed.lines()
    if result.interrupted:
        lines.append(f"interrupted: {result.finished} of {result.wanted} trials finished")
    return "\n".join(table + lines)


def _label(result: Result) -> str:
    """What the result's spec is: the study's best (so far), or the best of its best on fresh seeds."""
    if result.confirmed:
        return "kept (the best on fresh seeds, below)"
    return "best so far" if result.interrupted else "best"


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
