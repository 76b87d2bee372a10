"""A study's best trials and its defaults on fresh seeds: the seeds after the study's, the contenders (its best
distinct specs), the scores each episode's own (brute force), the one kept, the sources a seed changes only, the
verdict in each metric's direction, and the command's lines."""

import json

import optuna
import pytest

from helpers import write_sequence
from mtt_sim import cli
from mtt_sim.lab import tune
from mtt_sim.lab.confirm import CONTENDERS, Confirmation, confirm, fresh_seeds, simulated
from mtt_sim.lab.experiment import run_episode
from mtt_sim.metrics.goals import goals

SHORT = {"env.max_steps": 30}


def hota(source, spec, seed):
    return run_episode(source, spec, seed, SHORT)["metrics"]["HOTA"]


def made(metric, values, default, contenders=("sort:max_age=3", "sort:max_age=5")):
    values = [(v,) for v in values]
    return Confirmation(tuple(contenders), "sort", (2,), ("crossing",), tuple(goals(metric)), tuple(values),
                        (default,), (), ())


def test_fresh_seeds_follow_the_studys_largest():
    assert fresh_seeds([0, 1], 3) == (2, 3, 4) and fresh_seeds([7, 2], 2) == (8, 9) and fresh_seeds([], 1) == (0,)


def test_a_confirmed_study_keeps_the_best_of_its_best_trials_on_seeds_it_never_ran():
    sources, start = ["crossing", "clutter_storm"], "sort:min_hits=1"
    result, study = tune.tune(start, sources, "HOTA", trials=6, seeds=[0, 1], config=SHORT, confirm_seeds=2)
    c = result.confirmed
    assert c.seeds == (2, 3) and c.sources == tuple(sources) and len(c.contenders) == CONTENDERS
    done = sorted((t for t in study.trials if t.state == optuna.trial.TrialState.COMPLETE),
                  key=lambda t: (-t.values[0], t.number))
    assert c.contenders[0] == done[0].user_attrs["spec"]                       # the study's best first
    assert set(c.contenders) <= {t.user_attrs["spec"] for t in done[:CONTENDERS + 2]}
    fresh = {s: [[hota(src, s, seed) for seed in (2, 3)] for src in sources] for s in (*c.contenders, start)}
    mean = {s: sum(map(sum, v)) / 4 for s, v in fresh.items()}
    assert [v[0] for v in c.values] == pytest.approx([mean[s] for s in c.contenders])
    assert c.default_value[0] == pytest.approx(mean[start])
    assert result.spec == c.spec == max(c.contenders, key=lambda s: (mean[s], -c.contenders.index(s)))
    assert c.per_seed == pytest.approx([(fresh[c.spec][0][k] + fresh[c.spec][1][k]) / 2 for k in range(2)])
    kept = next(t for t in study.trials if t.user_attrs.get("spec") == result.spec)
    assert result.value == kept.values[0] and result.params == kept.params  # its study's score, as before
    assert result.as_dict()["confirmed"]["seeds"] == [2, 3] and c.holds == (mean[c.spec] > mean[start])
    assert result.kept == 0 and result.finished == 6  # no trial kept from an earlier run: a count, not the kept spec


def test_the_kept_contender_and_the_verdict_follow_each_metrics_direction():
    assert made("HOTA", [0.5, 0.6], 0.4).kept == 1 and made("HOTA", [0.6, 0.6], 0.4).kept == 0  # a tie: the first
    assert made("IDSW", [5, 3], 4).kept == 1 and made("IDSW", [5, 3], 4).holds                 # fewer is better
    assert not made("HOTA", [0.5, 0.4], 0.5).holds and not made("IDSW", [5, 4], 4).holds
    lines = made("HOTA", [0.5, 0.6], 0.7).lines()
    assert lines[0] == "on 1 fresh seed (2), HOTA: defaults 0.7" and lines[2].startswith("  kept 0.6  sort:max_age=5")
    assert "keep the defaults" in lines[-1] and "keep" not in " ".join(made("HOTA", [0.6], 0.5).lines())
    defaults_kept = made("HOTA", [0.5, 0.4], 0.5, ("sort", "sort:max_age=5")).lines()
    assert "(the defaults)" in defaults_kept[1] and "keep the defaults" not in defaults_kept[-1]


def test_only_sources_a_seed_changes_are_run_again(tmp_path):
    folder = write_sequence(tmp_path / "seq", det=[(f, 10, 10, 20, 40, 0.9) for f in range(1, 6)],
                            gt=[(f, 1, 10, 10, 20, 40, 1, 1, 1.0) for f in range(1, 6)])
    assert simulated([str(folder), "crossing"]) == ["crossing"]
    assert simulated([str(folder)], {"sensor.model": "synthetic"}) == [str(folder)]     # its twin
    assert confirm(["sort:max_age=3"], "sort", [str(folder)], goals("HOTA"), (1, 2)) is None


def test_the_command_prints_the_fresh_scores_and_refuses_what_it_cannot_confirm(tmp_path, capsys):
    assert cli.main(["tune", "sort", "--on", "crossing", "--trials", "4", "--confirm", "2", "--json",
                     "--config", "env.max_steps=30"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["confirmed"]["seeds"] == [1, 2] and printed["spec"] == printed["confirmed"]["spec"]
    assert cli.main(["tune", "sort", "--on", "crossing", "--trials", "2", "--confirm", "1",
                     "--config", "env.max_steps=30"]) == 0
    assert "on 1 fresh seed (1), HOTA: defaults" in capsys.readouterr().out
    assert cli.main(["tune", "sort", "--on", "crossing,clutter_storm", "--seeds", "2", "--confirm", "3",
                     "--dry-run"]) == 0
    estimate = capsys.readouterr().out.strip()
    assert estimate.endswith("then its best 3 and the defaults on 3 fresh seeds (at most 24 episodes)")
    folder = write_sequence(tmp_path / "seq", det=[(f, 10, 10, 20, 40, 0.9) for f in range(1, 6)],
                            gt=[(f, 1, 10, 10, 20, 40, 1, 1, 1.0) for f in range(1, 6)])
    assert cli.main(["tune", "sort", "--on", str(folder), "--confirm", "2"]) == 2
    err = capsys.readouterr().err
    assert "--confirm" in err and "nothing to confirm" in err and len(err.strip().splitlines()) == 1


def test_ctrl_c_during_the_confirmation_gives_the_studys_best_marked_interrupted(monkeypatch):
    from mtt_sim.lab import confirm as confirming

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(confirming, "run_tasks", interrupted)
    with pytest.raises(tune.Interrupted) as stop:
        tune.tune("sort", ["crossing"], "HOTA", trials=3, config=SHORT, confirm_seeds=2)
    plain, _ = tune.tune("sort", ["crossing"], "HOTA", trials=3, config=SHORT)
    got = stop.value.result
    assert got.interrupted and got.confirmed is None and got.spec == plain.spec and got.finished == 3
