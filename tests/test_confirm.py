"""A tuned spec held against its defaults on fresh seeds: the seeds after the study's, the scores each episode's own
(brute force), the sources a seed changes only, the verdict in each metric's direction, and the command's line."""

import json

import pytest

from helpers import write_sequence
from mtt_sim import cli
from mtt_sim.lab import tune
from mtt_sim.lab.confirm import Confirmation, confirm, fresh_seeds, simulated
from mtt_sim.lab.experiment import run_episode
from mtt_sim.metrics.goals import goals

SHORT = {"env.max_steps": 30}


def hota(source, spec, seed):
    return run_episode(source, spec, seed, SHORT)["metrics"]["HOTA"]


def test_fresh_seeds_follow_the_studys_largest():
    assert fresh_seeds([0, 1], 3) == (2, 3, 4) and fresh_seeds([7, 2], 2) == (8, 9) and fresh_seeds([], 1) == (0,)


def test_a_study_confirmed_scores_its_best_and_the_defaults_on_seeds_it_never_ran():
    result, _ = tune.tune("sort:min_hits=1", ["crossing", "clutter_storm"], "HOTA", trials=4, seeds=[0, 1],
                          config=SHORT, confirm_seeds=2)
    c = result.confirmed
    assert c.seeds == (2, 3) and c.sources == ("crossing", "clutter_storm")
    tuned = [[hota(s, result.spec, seed) for seed in (2, 3)] for s in c.sources]
    base = [[hota(s, "sort:min_hits=1", seed) for seed in (2, 3)] for s in c.sources]
    assert c.per_seed == pytest.approx([(tuned[0][k] + tuned[1][k]) / 2 for k in range(2)])
    assert c.default_per_seed == pytest.approx([(base[0][k] + base[1][k]) / 2 for k in range(2)])
    assert c.value[0] == pytest.approx(sum(map(sum, tuned)) / 4)
    assert c.default_value[0] == pytest.approx(sum(map(sum, base)) / 4)
    assert c.holds == (c.value[0] > c.default_value[0])
    assert result.as_dict()["confirmed"]["seeds"] == [2, 3]


def test_the_verdict_follows_each_metrics_direction():
    def made(metric, tuned, default, spec="sort:max_age=3"):
        return Confirmation(spec, "sort", (2,), ("crossing",), tuple(goals(metric)), (tuned,), (default,), (tuned,),
                            (default,))

    assert made("HOTA", 0.6, 0.5).holds and not made("HOTA", 0.5, 0.5).holds and not made("HOTA", 0.4, 0.5).holds
    assert made("IDSW", 3, 5).holds and not made("IDSW", 5, 3).holds      # fewer switches is better
    assert "keep the defaults" in made("HOTA", 0.4, 0.5).line() and "keep" not in made("HOTA", 0.6, 0.5).line()
    assert "on 1 fresh seed (2): HOTA 0.6, defaults 0.5" in made("HOTA", 0.6, 0.5).line()
    assert made("HOTA", 0.5, 0.5, "sort").line().endswith("HOTA 0.5 (the best is the defaults)")


def test_only_sources_a_seed_changes_are_run_again(tmp_path):
    folder = write_sequence(tmp_path / "seq", det=[(f, 10, 10, 20, 40, 0.9) for f in range(1, 6)],
                            gt=[(f, 1, 10, 10, 20, 40, 1, 1, 1.0) for f in range(1, 6)])
    assert simulated([str(folder), "crossing"]) == ["crossing"]
    assert simulated([str(folder)], {"sensor.model": "synthetic"}) == [str(folder)]     # its twin
    assert confirm("sort:max_age=3", "sort", [str(folder)], goals("HOTA"), (1, 2)) is None


def test_the_command_prints_the_fresh_scores_and_refuses_what_it_cannot_confirm(tmp_path, capsys):
    assert cli.main(["tune", "sort", "--on", "crossing", "--trials", "2", "--confirm", "2", "--json",
                     "--config", "env.max_steps=30"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["confirmed"]["seeds"] == [1, 2]
    assert cli.main(["tune", "sort", "--on", "crossing", "--trials", "2", "--confirm", "1",
                     "--config", "env.max_steps=30"]) == 0
    assert "on 1 fresh seed (1): HOTA" in capsys.readouterr().out
    assert cli.main(["tune", "sort", "--on", "crossing,clutter_storm", "--seeds", "2", "--confirm", "3",
                     "--dry-run"]) == 0
    assert capsys.readouterr().out.strip().endswith("then the best and the defaults on 3 fresh seeds (12 episodes)")
    folder = write_sequence(tmp_path / "seq", det=[(f, 10, 10, 20, 40, 0.9) for f in range(1, 6)],
                            gt=[(f, 1, 10, 10, 20, 40, 1, 1, 1.0) for f in range(1, 6)])
    assert cli.main(["tune", "sort", "--on", str(folder), "--confirm", "2"]) == 2
    err = capsys.readouterr().err
    assert "--confirm" in err and "nothing to confirm" in err and len(err.strip().splitlines()) == 1
