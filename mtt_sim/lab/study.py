"""A stored study: what defines a tuning, and the Optuna study kept for it, checked, with its interrupted trials.

A study remembers what defines it (the spec, the sources, the metrics, the seeds, the overrides, the search space):
the default study name carries a digest of it, and a stored study made for another definition is refused, saying
what differs, never mixed. A trial cut short (Ctrl-C, or a process of this machine that died in it) is marked
interrupted: it does not count towards the trials wanted and is queued again, so that a resumed study runs what an
uninterrupted one would have. Kept apart from running a tuning (`mtt_sim.lab.tune`): what a study is, and whether
a stored one may be resumed, does not depend on how its trials are drawn and run.
"""

from __future__ import annotations

import hashlib
import json
import os
import socket
from pathlib import Path
from typing import Callable, Mapping, Sequence

from mtt_sim.metrics.goals import Goal, goals
from mtt_sim.trackers.base import TrackerSpec, plugins, search_space, spec_of


def definition(spec: str, sources: Sequence[str], metric: str = "HOTA", seeds: Sequence[int] = (0,),
               config: Mapping | None = None) -> tuple[dict, str]:
    """What defines a study, as stored with it, and its digest (8 hex digits): everything that changes a trial's
    value or what is searched. The tracker with its fixed parameters, the sources (a TOML file with its content's
    digest), the metrics with their directions, the seeds, the overrides (dotted keys) and the search space."""
    spec = TrackerSpec.of(spec)
    name, fixed = spec.name, spec.params
    space = search_space(name, fixed)
    canonical = name if plugins.is_location(name) else spec.registered
    out = {"tracker": spec_of(canonical, {k: spec.values[k] for k in sorted(fixed)}),
           "sources": [_source(s) for s in sources],
           "metric": ", ".join(("maximize " if g.maximize else "minimize ") + g.metric for g in goals(metric)),
           "seeds": sorted(int(s) for s in seeds),
           "config": dict(sorted(_dotted(config or {}).items())),
           "space": {k: [type(p.default).__name__, *p.search] for k, p in sorted(space.items())}}
    out = json.loads(json.dumps(out, default=str))  # as the storage gives it back
    digest = hashlib.sha256(json.dumps(out, sort_keys=True, separators=(",", ":")).encode()).hexdigest()[:8]
    return out, digest


def default_study_name(spec: str, sources: Sequence[str], metric: str, digest: str) -> str:
    """'sort on crossing for HOTA (1a2b3c4d)': the tracker, the sources, the metrics and the definition's digest."""
    spec = TrackerSpec.of(spec)
    tracker = spec.name if plugins.is_location(spec.name) else spec.registered
    return f"{tracker} on {','.join(map(str, sources))} for {','.join(g.text for g in goals(metric))} ({digest})"


def _source(source) -> str:
    """A source as the definition names it: a scenario key in its canonical case, a folder or a file as given, and
    a TOML file with the digest of its content (an edited scene is another scene)."""
    from mtt_sim import sources as known

    try:
        resolved = known.resolve(source)
    except Exception:  # noqa: BLE001  (an unknown source fails in its trial, as before; here it is only named)
        return str(source)
    path = Path(resolved)
    if isinstance(resolved, Path) and path.is_file():
        return f"{resolved} (sha256 {hashlib.sha256(path.read_bytes()).hexdigest()[:12]})"
    return str(resolved)


def _dotted(config: Mapping, prefix: str = "") -> dict:
    """Nested overrides as dotted keys: {"sensor": {"pd": 0.8}} and {"sensor.pd": 0.8} name one definition."""
    out = {}
    for key, value in config.items():
        if isinstance(value, Mapping):
            out.update(_dotted(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def open_storage(url: str | None):
    """The Optuna storage at `url` (None: in memory), or a ValueError naming the URL and what went wrong."""
    import optuna

    if url is None:
        return None
    try:
        return optuna.storages.get_storage(url)
    except Exception as err:  # noqa: BLE001  (SQLAlchemy's errors for a URL it cannot parse or open are many)
        raise ValueError(f"storage {url!r}: {str(err).splitlines()[0]} (e.g. sqlite:///study.db)") from None


def open_study(store, study_name: str, own_name: str, defined: dict, digest: str, wanted: list[Goal], trials: int,
               defaults: Mapping, say: Callable[[str], None], sampler):
    """The study `study_name` in `store`, made for `defined` or refused, with its interrupted trials queued again;
    and the number of finished trials it already had. A new study queues its defaults first. `sampler` is the one
    the study is made with (the caller sets each trial's own)."""
    import optuna

    directions = ["maximize" if g.maximize else "minimize" for g in wanted]
    if store is not None:
        try:
            study_id = store.get_study_id_from_name(study_name)
        except KeyError:
            study_id = None
        if study_id is not None:
            _check(store, study_id, study_name, own_name, defined, directions)
    study = optuna.create_study(storage=store, study_name=study_name, load_if_exists=True, directions=directions,
                                sampler=sampler,
                                pruner=optuna.pruners.MedianPruner(n_startup_trials=5) if len(wanted) == 1
                                else optuna.pruners.NopPruner())
    if "definition" not in study.user_attrs:
        from mtt_sim import __version__

        study.set_user_attr("definition", defined)
        study.set_user_attr("digest", digest)
        study.set_user_attr("mtt_sim", __version__)  # for the record: a study is not refused for another version
    existing = study.trials
    if not existing:
        study.enqueue_trial(dict(defaults), user_attrs={"defaults": True})
        return study, 0
    for t in existing:
        if t.state == optuna.trial.TrialState.RUNNING and _abandoned(t):
            mark_interrupted(study, t, store)
    existing = study.trials
    finished = counted(existing)
    rerun = _rerun(study, existing, set(defaults))
    running = [t for t in existing if t.state == optuna.trial.TrialState.RUNNING]
    parts = [_many(len(finished), "finished trial") + " kept"]
    if rerun:
        parts.append(_many(rerun, "interrupted trial") + " rerun first")
    if running:
        parts.append(_many(len(running), "trial") + " still marked running, left to the process running it")
    more = max(0, trials - len(finished))
    say(f"resuming study {study_name!r}: {', '.join(parts)}; "
        + (f"{_many(more, 'trial')} to go for {trials}" if more else f"nothing left to run for {trials}"))
    return study, len(finished)


def _check(store, study_id: int, study_name: str, own_name: str, defined: dict, directions: list[str]) -> None:
    """A stored study may be resumed only for the definition it was made for; a ValueError says what differs."""
    how = "give another --study-name" + (f", or drop --study-name for this tuning's own study {own_name!r}"
                                         if study_name != own_name else "")
    stored = store.get_study_user_attrs(study_id).get("definition")
    trials = store.get_all_trials(study_id, deepcopy=False)
    if stored is None:
        if not trials:  # made empty elsewhere (optuna create-study, say): this tuning's, if its directions agree
            made = [d.name.lower() for d in store.get_study_directions(study_id)]
            if made == directions:
                return
            raise ValueError(f"study {study_name!r} is empty but made to {', '.join(made)}, and this tuning would "
                             f"{', '.join(directions)}: {how}")
        raise ValueError(f"study {study_name!r} has {_many(len(trials), 'trial')} but no stored definition (it was "
                         "made before mtt-sim kept one), so whether they were scored as this tuning scores cannot be "
                         f"checked, and it is not resumed: {how}")
    if stored != defined:
        changed = "; ".join(_differences(stored, defined))
        raise ValueError(f"study {study_name!r} was made for another tuning ({changed}) and its trials would mix with "
                         f"this one's, so it is not resumed: {how}")


def _differences(old: Mapping, new: Mapping) -> list[str]:
    """'metric: was 'maximize HOTA', now 'maximize MOTA'' for each field that differs (each key of a table)."""
    def show(table, key):
        if key not in table:
            return "(none)"
        return repr(table[key]) if isinstance(table[key], str) else json.dumps(table[key])

    out = []
    for key in dict.fromkeys([*old, *new]):
        a, b = old.get(key), new.get(key)
        if a == b:
            continue
        if isinstance(a, Mapping) and isinstance(b, Mapping):
            out += [f"{key} {sub}: was {show(a, sub)}, now {show(b, sub)}"
                    for sub in dict.fromkeys([*a, *b]) if a.get(sub, ...) != b.get(sub, ...)]
        else:
            out.append(f"{key}: was {show(old, key)}, now {show(new, key)}")
    return out


def _interrupted(trial) -> bool:
    import optuna

    return trial.state == optuna.trial.TrialState.FAIL and bool(trial.user_attrs.get("interrupted"))


def state(trial) -> str:
    """A trial's state as a study tells it: 'complete', 'pruned', 'fail', 'running', 'waiting', or 'interrupted'."""
    return "interrupted" if _interrupted(trial) else trial.state.name.lower()


def counted(trials) -> list:
    """The finished trials that count towards `trials`: complete, pruned, or failed by their own error."""
    return [t for t in trials if t.state.is_finished() and not _interrupted(t)]


def _rerun(study, trials, keys: set) -> int:
    """Queue again each interrupted trial that nothing has rerun yet (its parameters, and its being the defaults),
    so that the study ends as an uninterrupted one would; the number of reruns queued, these and earlier ones."""
    import optuna

    origin = lambda t: t.user_attrs.get("rerun_of", t.number)  # noqa: E731
    settled = {origin(t) for t in trials if not _interrupted(t)}  # finished, queued or running
    queued = sum(t.state == optuna.trial.TrialState.WAITING and "rerun_of" in t.user_attrs for t in trials)
    for t in trials:
        if _interrupted(t) and origin(t) not in settled and set(t.params) == keys:
            study.enqueue_trial(dict(t.params), user_attrs={"rerun_of": origin(t),
                                                            **({"defaults": True} if t.user_attrs.get("defaults")
                                                               else {})})
            settled.add(origin(t))
            queued += 1
    return queued


def _abandoned(trial) -> bool:
    """A trial marked running by a process of this machine that is gone (killed without a chance to say so)."""
    runner = trial.user_attrs.get("runner")
    if os.name != "posix" or not isinstance(runner, dict) or runner.get("host") != socket.gethostname():
        return False  # another machine's trial may well be running
    pid = runner.get("pid")
    if not isinstance(pid, int) or pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:  # there, but another user's
        return False
    return False


def mark_interrupted(study, trial, store=None) -> None:
    """Mark a running trial (a live Optuna trial, or a stored one in `store`) interrupted: failed, not counted."""
    import optuna

    if store is None:
        trial.set_user_attr("interrupted", True)
    else:
        store.set_trial_user_attr(trial._trial_id, "interrupted", True)
    study.tell(trial.number, state=optuna.trial.TrialState.FAIL, skip_if_finished=True)


def _many(n: int, noun: str) -> str:
    return f"{n} {noun}" + ("" if n == 1 else "s")
