"""`mtt-sim tune`: the metric goals, the spec a study writes, one seed one study (whatever the workers), a tuned spec
that beats its defaults where they are known to be poor, failed trials, resumed studies, the command line."""

import json
import tomllib

import numpy as np
import pytest

from mtt_sim import cli, trackers
from mtt_sim.lab import tune
from mtt_sim.lab.experiment import run_episode
from mtt_sim.metrics.goals import Goal, goals
from mtt_sim.trackers.base import parse_spec, spec_of

SHORT = {"env.max_steps": 40}
# four still targets and a storm of clutter whose confidence (0.2) sits far below the targets' (0.95): SORT's default
# min_confidence=0 reports the clutter, a threshold between the two does not
STORM = {**SHORT, "sensor.clutter_rate": 8.0, "sensor.conf_false": 0.2, "sensor.conf_true": 0.95}


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
