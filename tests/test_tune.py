"""`mtt-sim tune`: the metric goals, the spec a study writes, one seed one study (whatever the workers), a tuned spec
that beats its defaults where they are known to be poor, failed trials, resumed studies, the command line; a study's
definition (its default name, another one refused), interrupted trials (marked, not counted, rerun first, the
resumed study as an uninterrupted one), Ctrl-C on the command (the best so far, --out, status 130), a study in which
every trial failed (why, in one line, and status 1)."""

import json
import os
import signal
import socket
import subprocess
import sys
import time
import tomllib

import numpy as np
import optuna
import pytest

from mtt_sim import cli, trackers
from mtt_sim.lab import tune
from mtt_sim.lab.experiment import run_episode
from mtt_sim.lab.study import default_study_name, definition
from mtt_sim.metrics.goals import Goal, goals
from mtt_sim.trackers.base import parse_spec, spec_of

SHORT = {"env.max_steps": 40}
# four still targets and a storm of clutter whose confidence (0.2) sits far below the targets' (0.95): SORT's default
# min_confidence=0 reports the clutter, a threshold between the two does not
STORM = {**SHORT, "sensor.clutter_rate": 8.0, "sensor.conf_false": 0.2, "sensor.conf_true": 0.95}
TINY = {"env.max_steps": 5}  # a trial of a tenth of a second: what a study's bookkeeping needs, not what it finds


def interrupt_at(monkeypatch, call):
    """Ctrl-C as the study sees it: KeyboardInterrupt from its `call`-th batch of episodes (1 = the first trial's)."""
    run_tasks, calls = tune.run_tasks, []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == call:
            raise KeyboardInterrupt
        return run_tasks(*args, **kwargs)

    monkeypatch.setattr(tune, "run_tasks", interrupted)


def test_each_metric_is_optimised_in_its_natural_direction_unless_signed():
    assert goals("hota") == [Goal("HOTA", True)]
    assert goals("HOTA,-IDSW") == [Goal("HOTA", True), Goal("IDSW", False)]
    assert goals("IDSW") == [Goal("IDSW", False)] and goals("+FP") == [Goal("FP", True)]
    assert [g.text for g in goals("MOTA,IDSW,+FN,-IDF1")] == ["MOTA", "IDSW", "+FN", "-IDF1"]
    with pytest.raises(ValueError, match="unknown metric 'HOTTA'"):
        goals("HOTTA")
    with pytest.raises(ValueError, match="each once"):
        goals("HOTA,hota")


def test_a_spec_written_back_parses_to_the_same_parameters():
    params = {"max_age": 17, "iou_threshold": 0.44179619444656, "min_confidence": 0.1}
    text = spec_of("sort", params)
    assert text == "sort:max_age=17,iou_threshold=0.44179619444656,min_confidence=0.1"
    assert trackers.make(text).params == {**trackers.make("sort").params, **params}
    assert spec_of("lmb", {"reid": False}) == "lmb:reid=false" and parse_spec(spec_of("iou", {})) == ("iou", {})


def test_tuning_beats_defaults_that_report_the_clutter_and_the_spec_scores_as_found():
    result, study = tune.tune("sort", ["clutter_storm"], "MOTA", trials=12, config=STORM)
    assert result.default_value == run_episode("clutter_storm", "sort", 0, STORM)["metrics"]["MOTA"]
    assert result.value > result.default_value + 0.2, result  # the defaults report most of the clutter
    assert 0.2 < result.params["min_confidence"] < 0.95  # between the clutter's confidence and the targets'
    assert run_episode("clutter_storm", result.spec, 0, STORM)["metrics"]["MOTA"] == result.value
    assert result.trials["complete"] + result.trials.get("pruned", 0) == 12 == len(study.trials)


def test_one_seed_gives_one_study_whatever_the_workers():
    def history(seed, workers):
        result, study = tune.tune("iou", ["crossing", "clutter_storm"], "IDF1", trials=4, seeds=[0, 1], config=SHORT,
                                  seed=seed, workers=workers)
        return result.as_dict(), [(t.params, t.values) for t in study.trials]

    first = history(3, 1)
    assert history(3, 1) == first == history(3, 2)
    assert history(4, 1)[1][1:] != first[1][1:]  # after the defaults, another seed draws other trials


def test_a_trial_that_raises_is_recorded_as_failed_and_the_study_goes_on(monkeypatch):
    update = trackers.sort.Sort.update

    def fragile(self, obs):
        if self.params["max_age"] > 15:
            raise RuntimeError("too old")
        return update(self, obs)

    monkeypatch.setattr(trackers.sort.Sort, "update", fragile)
    result, study = tune.tune("sort", ["crossing"], "HOTA", trials=10, config=SHORT, seed=1)
    failed = [t for t in study.trials if t.state.name == "FAIL"]
    assert failed and result.trials["fail"] == len(failed) and result.params["max_age"] <= 15
    assert all("too old" in t.user_attrs["error"] for t in failed)


def test_a_stored_study_resumes_without_running_the_defaults_again(tmp_path):
    storage = f"sqlite:///{tmp_path / 'study.db'}"
    first, _ = tune.tune("sort", ["crossing"], "HOTA", trials=3, config=SHORT, storage=storage, study_name="s")
    again, study = tune.tune("sort", ["crossing"], "HOTA", trials=6, config=SHORT, storage=storage, study_name="s")
    assert len(study.trials) == 6 and sum(t.user_attrs.get("defaults", False) for t in study.trials) == 1
    assert again.default_value == first.default_value and again.value >= first.value


def test_several_metrics_give_a_pareto_front():
    result, _ = tune.tune("sort", ["crossing"], "HOTA,-IDSW", trials=6, config=SHORT)
    assert isinstance(result.value, list) and len(result.value) == 2 and result.front
    values = [f["value"] for f in result.front]
    for hota, idsw in values:  # nobody on the front is beaten in both metrics by another
        assert not any(h >= hota and i <= idsw and (h, i) != (hota, idsw) for h, i in values)


def test_a_spec_with_nothing_left_to_search_says_so():
    with pytest.raises(ValueError, match="no tunable parameter left"):
        tune.tune("sort:max_age=1,min_hits=3,iou_threshold=0.3,min_confidence=0", ["crossing"], trials=2)


def test_the_command_prints_json_writes_toml_and_refuses_a_bad_metric(tmp_path, capsys):
    out = tmp_path / "best.toml"
    assert cli.main(["tune", "sort:min_hits=1", "--on", "crossing", "--trials", "3", "--json", "--out", str(out),
                     "--config", "env.max_steps=30"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert {"spec", "value", "default_value", "trials", "params"} <= set(printed) and printed["trials"] == 3
    assert printed["spec"].startswith("sort:min_hits=1,") and "min_hits" not in printed["params"]
    written = tomllib.loads(out.read_text())
    assert written["spec"] == printed["spec"] and written["params"] == printed["params"]
    assert np.isclose(written["value"], printed["value"]) and trackers.make(written["spec"])
    with pytest.raises(SystemExit) as exit_:
        cli.main(["tune", "sort", "--on", "crossing", "--metric", "HOTTA"])
    assert exit_.value.code == 2 and "unknown metric 'HOTTA'" in capsys.readouterr().err
    assert cli.main(["tune", "sort", "--on", "crossing", "--storage", "nowhere", "--trials", "2"]) == 2
    assert "storage 'nowhere': Could not parse" in capsys.readouterr().err


def test_a_stored_study_refuses_another_definition_under_its_name_before_any_trial(tmp_path):
    storage = f"sqlite:///{tmp_path / 'study.db'}"
    tune.tune("sort", ["mot17_like"], "HOTA", trials=1, config=TINY, storage=storage, study_name="s")
    changes = {"metric": dict(metric="MOTA"), "seeds": dict(seeds=[0, 1]),
               "config env.max_steps": dict(config={"env.max_steps": 6}),
               "config sensor.clutter_rate": dict(config={**TINY, "sensor.clutter_rate": 3}),  # --sensor, --detector
               "tracker": dict(spec="sort:max_age=5"), "sources": dict(sources=["clutter_storm"])}
    for field, change in changes.items():
        args = {"spec": "sort", "sources": ["mot17_like"], "metric": "HOTA", "config": TINY, **change}
        with pytest.raises(ValueError) as refused:
            tune.tune(**args, trials=3, storage=storage, study_name="s")
        message = str(refused.value)
        assert f"; {field}: was " in message or f"({field}: was " in message, (field, message)
        assert "\n" not in message and "give another --study-name, or drop --study-name for this tuning's own study " \
            f"'{default_study_name(args['spec'], args['sources'], args['metric'], definition(**args)[1])}'" \
            in message
    with pytest.raises(ValueError, match=r"metric: was 'maximize HOTA', now 'maximize MOTA'\)"):
        tune.tune("sort", ["mot17_like"], "MOTA", trials=3, config=TINY, storage=storage, study_name="s")
    with pytest.raises(ValueError, match=r"tracker: was 'sort', now 'sort:max_age=5'; space max_age: was "
                                         r"\[\"int\", 1, 30\], now \(none\)"):
        tune.tune("sort:max_age=5", ["mot17_like"], trials=3, config=TINY, storage=storage, study_name="s")
    assert len(optuna.load_study(study_name="s", storage=storage).trials) == 1  # refused before any trial
    again, study = tune.tune("sort", ["mot17_like"], "HOTA", trials=2, config={"env": {"max_steps": 5}},
                             storage=storage, study_name="s")  # the same overrides, nested: the same definition
    assert len(study.trials) == 2 and again.study == "s"


def test_a_study_without_a_stored_definition_is_refused_unless_it_is_empty(tmp_path):
    storage = f"sqlite:///{tmp_path / 'study.db'}"
    old = optuna.create_study(storage=storage, study_name="old", direction="maximize")
    old.enqueue_trial({"max_age": 3})
    old.optimize(lambda trial: trial.suggest_int("max_age", 1, 30) / 30, n_trials=1)  # as the old code left it
    with pytest.raises(ValueError, match="study 'old' has 1 trial but no stored definition .* not resumed: give "
                                         "another --study-name, or drop --study-name"):
        tune.tune("sort", ["mot17_like"], trials=2, config=TINY, storage=storage, study_name="old")
    optuna.create_study(storage=storage, study_name="empty", direction="maximize")
    result, study = tune.tune("sort", ["mot17_like"], trials=1, config=TINY, storage=storage, study_name="empty")
    assert study.user_attrs["definition"] == definition("sort", ["mot17_like"], "HOTA", [0], TINY)[0]
    optuna.create_study(storage=storage, study_name="down", direction="minimize")
    with pytest.raises(ValueError, match="study 'down' is empty but made to minimize, and this tuning would maximize"):
        tune.tune("sort", ["mot17_like"], trials=1, config=TINY, storage=storage, study_name="down")


def test_the_default_study_name_carries_a_digest_of_the_definition(tmp_path, capsys):
    first, digest = definition("sort", ["mot17_like"], "HOTA", [0], TINY)
    assert definition("sort", ["mot17_like"], "HOTA", [0], {"env": {"max_steps": 5}}) == (first, digest)
    for other in (dict(metric="MOTA"), dict(seeds=[1]), dict(config={"env.max_steps": 6}),
                  dict(spec="sort:min_hits=1"), dict(metric="HOTA,-IDSW"), dict(sources=["mot17_like", "crossing"])):
        args = {"spec": "sort", "sources": ["mot17_like"], "metric": "HOTA", "seeds": [0], "config": TINY, **other}
        assert definition(**args)[1] != digest, other
    scene = tmp_path / "scene.toml"  # a scene file is named by its content too: an edited scene is another study
    scene.write_text('extends = "mot17_like"\n')
    before = definition("sort", [str(scene)])[1]
    scene.write_text('extends = "mot17_like"\n[sensor]\npd = 0.8\n')
    assert definition("sort", [str(scene)])[1] != before
    storage = f"sqlite:///{tmp_path / 'study.db'}"
    hota, _ = tune.tune("sort", ["mot17_like"], "HOTA", trials=1, config=TINY, storage=storage)
    mota, _ = tune.tune("sort", ["mot17_like"], "MOTA", trials=1, config=TINY, storage=storage)
    assert hota.study == f"sort on mot17_like for HOTA ({digest})"
    assert mota.study.startswith("sort on mot17_like for MOTA (") and mota.study != hota.study
    assert sorted(optuna.get_all_study_names(storage)) == sorted([hota.study, mota.study])
    assert cli.main(["tune", "sort", "--on", "mot17_like", "--trials", "2", "--config", "env.max_steps=5",
                     "--storage", storage]) == 0
    out, err = capsys.readouterr()
    assert f"\nstudy: {hota.study}\n" in out and f"resuming study '{hota.study}': 1 finished trial kept; 1 trial " \
        "to go for 2" in err


def test_an_interrupted_trial_is_not_counted_and_the_resumed_study_is_the_uninterrupted_one(tmp_path, monkeypatch):
    sources, trials = ["mot17_like", "clutter_storm"], 12  # two sources: pruning; twelve trials: TPE past its start
    _, whole = tune.tune("sort", sources, trials=trials, config=TINY)
    storage, said = f"sqlite:///{tmp_path / 'study.db'}", []
    interrupt_at(monkeypatch, 12)  # within the sixth or a later trial, as some were pruned after their first source
    with pytest.raises(tune.Interrupted) as stop:
        tune.tune("sort", sources, trials=trials, config=TINY, storage=storage, study_name="s", say=said.append)
    cut = stop.value.study.trials[-1]
    assert cut.state.name == "FAIL" and cut.user_attrs["interrupted"] and "error" not in cut.user_attrs
    kept = len(stop.value.study.trials) - 1
    assert stop.value.result.interrupted and stop.value.result.finished == kept >= 5 and not said
    assert stop.value.result.trials["interrupted"] == 1
    monkeypatch.undo()
    result, study = tune.tune("sort", sources, trials=trials, config=TINY, storage=storage, study_name="s",
                              say=said.append)
    assert said == [f"resuming study 's': {kept} finished trials kept, 1 interrupted trial rerun first; "
                    f"{trials - kept} trials to go for {trials}"]
    assert result.finished == trials == len(study.trials) - 1 and result.kept == kept and not result.interrupted
    rerun = study.trials[kept + 1]
    assert rerun.params == cut.params and rerun.user_attrs["rerun_of"] == cut.number
    def counted(s):
        return [(t.params, t.state.name, t.values) for t in s.trials if not t.user_attrs.get("interrupted")]

    assert {t.state.name for t in whole.trials} == {"COMPLETE", "PRUNED"}
    assert counted(study) == counted(whole)  # the same trials, the same scores, the same prunings
    found = tune._result(whole, "sort", {}, result.goals)
    assert (result.spec, result.value, result.default_value) == (found.spec, found.value, found.default_value)


def test_the_interrupted_defaults_are_rerun_as_the_defaults(tmp_path, monkeypatch):
    storage = f"sqlite:///{tmp_path / 'study.db'}"
    interrupt_at(monkeypatch, 1)
    with pytest.raises(tune.Interrupted) as stop:
        tune.tune("sort", ["mot17_like"], trials=2, config=TINY, storage=storage, study_name="s")
    assert stop.value.result is None and stop.value.study.trials[0].user_attrs == {
        "defaults": True, "interrupted": True, "runner": {"host": socket.gethostname(), "pid": os.getpid()},
        "spec": "sort:max_age=1,min_hits=3,iou_threshold=0.3,min_confidence=0.0"}
    monkeypatch.undo()
    result, study = tune.tune("sort", ["mot17_like"], trials=2, config=TINY, storage=storage, study_name="s")
    assert study.trials[1].user_attrs["defaults"] and result.default_value is not None
    assert result.default_value == study.trials[1].value and result.trials == {"complete": 2, "interrupted": 1}


def test_a_trial_left_running_by_a_dead_process_is_rerun_and_another_machines_left_alone(tmp_path):
    storage = f"sqlite:///{tmp_path / 'study.db'}"
    _, study = tune.tune("sort", ["mot17_like"], trials=1, config=TINY, storage=storage, study_name="s")
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    killed = study.ask(fixed_distributions=study.trials[0].distributions)  # as `kill -9` in its episodes left it
    killed.set_user_attr("runner", {"host": socket.gethostname(), "pid": gone.pid})
    elsewhere = study.ask(fixed_distributions=study.trials[0].distributions)
    elsewhere.set_user_attr("runner", {"host": "another-machine", "pid": gone.pid})
    said = []
    result, study = tune.tune("sort", ["mot17_like"], trials=2, config=TINY, storage=storage, study_name="s",
                              say=said.append)
    assert said == ["resuming study 's': 1 finished trial kept, 1 interrupted trial rerun first, 1 trial still marked "
                    "running, left to the process running it; 1 trial to go for 2"]
    states = [(t.state.name, t.user_attrs.get("interrupted"), t.user_attrs.get("rerun_of")) for t in study.trials]
    assert states == [("COMPLETE", None, None), ("FAIL", True, None), ("RUNNING", None, None), ("COMPLETE", None, 1)]
    assert study.trials[3].params == study.trials[1].params and result.finished == 2


def test_ctrl_c_is_held_while_the_study_is_written_and_stops_the_episodes_at_once():
    interrupts = tune._Interrupts()
    previous = signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))  # as the CLI's
    # Python's own Ctrl-C handler, which a process started in the background of a script (SIGINT ignored) lacks
    ignored = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with interrupts.held():
            for sig in (signal.SIGINT, signal.SIGTERM):
                os.kill(os.getpid(), sig)
                time.sleep(0.05)  # delivered here, and held
            with pytest.raises(KeyboardInterrupt):
                interrupts.check()
            interrupts.check()  # once
            with pytest.raises(KeyboardInterrupt):
                with interrupts.allowed():
                    os.kill(os.getpid(), signal.SIGINT)
                    time.sleep(5)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGTERM, previous)
        signal.signal(signal.SIGINT, ignored)


def test_ctrl_c_on_the_command_reports_the_best_so_far_writes_out_and_exits_130(tmp_path, capsys, monkeypatch):
    storage, out = f"sqlite:///{tmp_path / 'study.db'}", tmp_path / "best.toml"
    command = ["tune", "sort", "--on", "mot17_like", "--trials", "5", "--config", "env.max_steps=5", "--storage",
               storage, "--study-name", "s"]
    interrupt_at(monkeypatch, 1)
    assert cli.main(command + ["--out", str(out)]) == 130
    printed, err = capsys.readouterr()
    assert "best" not in printed and "Traceback" not in err and not out.exists()
    assert err.splitlines()[-1] == "mtt-sim tune: interrupted before any trial finished; the same command resumes " \
        "study 's'"
    interrupt_at(monkeypatch, 3)  # the third trial, after two finished (the first interruption's rerun the first)
    assert cli.main(command + ["--out", str(out)]) == 130
    printed, err = capsys.readouterr()
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert err.splitlines()[-1] == "mtt-sim tune: interrupted; 2 of 5 trials finished; the same command resumes " \
        "study 's'"
    assert "\nbest so far: sort:" in printed and printed.splitlines()[-2:] == [
        "interrupted: 2 of 5 trials finished", f"result: {out}"]
    written = tomllib.loads(out.read_text())
    assert written["interrupted"] is True and written["trials"] == 2 and written["trials_wanted"] == 5
    assert written["study"] == "s" and trackers.make(written["spec"])
    monkeypatch.undo()
    assert cli.main(command + ["--json"]) == 0
    printed, err = capsys.readouterr()
    assert "resuming study 's': 2 finished trials kept, 1 interrupted trial rerun first; 3 trials to go for 5" in err
    assert json.loads(printed)["trials"] == 5 and json.loads(printed)["interrupted"] is False
    assert json.loads(printed)["states"] == {"complete": 5, "interrupted": 2}
    assert cli.main(command + ["--metric", "MOTA"]) == 2
    err = capsys.readouterr().err
    assert err.splitlines()[-1].startswith("mtt-sim tune: error: study 's' was made for another tuning (metric: was "
                                           "'maximize HOTA', now 'maximize MOTA') and its trials would mix")


def test_a_study_in_which_every_trial_failed_says_why_in_one_line_and_exits_1(monkeypatch, capsys):
    def failing(tasks, *args, **kwargs):
        return [{"scenario": t[0], "error": "RuntimeError: the scene fell over\n  at frame 3", "metrics": None}
                for t in tasks]

    monkeypatch.setattr(tune, "run_tasks", failing)
    with pytest.raises(tune.NoTrialFinished, match=r"^no trial finished: RuntimeError: the scene fell over$"):
        tune.tune("sort", ["mot17_like"], trials=2, config=TINY)
    assert cli.main(["tune", "sort", "--on", "mot17_like", "--trials", "2", "--config", "env.max_steps=5",
                     "--json"]) == 1
    printed, err = capsys.readouterr()
    assert printed == "" and "Traceback" not in err
    assert err.splitlines()[-3:] == ["trial 0 failed: RuntimeError: the scene fell over",
                                     "trial 1 failed: RuntimeError: the scene fell over",
                                     "mtt-sim tune: error: no trial finished: RuntimeError: the scene fell over"]
