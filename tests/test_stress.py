"""`mtt-sim stress`: searched keys checked against the config's own ranges, objectives over metrics and trackers, a
search that finds a known worst corner, one seed one search (whatever the workers), worst scenes that rerun to their
value from their TOML and seed, and the command line."""

import json

import pytest

from helpers import exit_code
from mtt_sim import cli
from mtt_sim.lab import stress
from mtt_sim.lab.experiment import run_episode
from mtt_sim.sim import scenario
from mtt_sim.core.settings import ConfigError

SHORT = {"env.max_steps": 30}


def test_a_key_names_one_value_of_the_scenario_with_its_type_and_range():
    assert scenario.setting_of("sensor.pd")[0] is float and scenario.setting_of("sensor.pd")[1]["hi"] == 1.0
    assert scenario.setting_of("groups.0.count")[0] is int
    assert scenario.setting_of("groups.3.size.1")[0] is float  # the item's existence is the scenario's business
    assert scenario.setting_of("render.camera")[1]["choices"] == ("static", "pan", "follow", "shake", "trace", "walking",
                                                                "still")
    for key, message in [("sensor.pdd", "no key sensor.pdd; allowed: sensor.model"),
                         ("groups.x.count", "groups is a list: expected an item's index, got 'x'"),
                         ("sensor", "a table or a list"), ("groups.0.size.2", "expected an item's index, got '2'"),
                         ("sensor.pd.0", "sensor.pd is a single value")]:
        with pytest.raises(ConfigError, match=message.replace(".", r"\.").replace("(", r"\(")):
            scenario.setting_of(key)


def test_searched_keys_are_checked_against_the_keys_own_ranges_and_choices():
    assert stress.dimension("sensor.pd=0.5:0.9") == stress.Dimension("sensor.pd", float, 0.5, 0.9)
    assert stress.dimension("groups.0.count = 2:30") == stress.Dimension("groups.0.count", int, 2, 30)
    assert stress.dimension("render.camera=static|SHAKE").choices == ("static", "shake")
    assert stress.dimension("world.walls").choices == (False, True)
    assert stress.dimension("scoring.reward_mode").choices == ("mota", "gospa", "iou")
    for text, message in [("sensor.pd=0.5:1.5", r"within the key's range 0.0..1.0"),
                          ("sensor.pd=0.9:0.5", "LO < HI"), ("sensor.pd=0.5", "float bounds"),
                          ("groups.0.count=2.5:9", "int bounds"), ("render.camera=static|zoom", "'zoom' is not one of render.camera's choices"),
                          ("render.camera=static|shkae", r"'shkae' .* \(did you mean 'shake'\?\); allowed: static\|pan"),
                          ("render.camera=shake", "two or more of"), ("groups.0.name", "without a list of choices"),
                          ("sensor.ppd=0:1", "no key sensor.ppd")]:
        with pytest.raises(ConfigError, match=message):
            stress.dimension(text)


def test_an_objective_is_arithmetic_over_metrics_of_named_trackers():
    alone = stress.Objective("-mota", "sort")
    assert alone.terms == [("MOTA", "sort")] and alone.specs == ["sort"]
    assert alone.value({"sort": {"MOTA": 0.25}}) == -0.25
    gap = stress.Objective("MOTA[sort] - MOTA[lmb:reid=false]", "sort")
    assert gap.specs == ["sort", "lmb:reid=false"]
    assert gap.value({"sort": {"MOTA": 0.5}, "lmb:reid=false": {"MOTA": 0.75}}) == -0.25
    mixed = stress.Objective("2 * IDSW + FN / 10 - (FP)", "iou")
    assert mixed.value({"iou": {"IDSW": 3, "FN": 40, "FP": 1}}) == 9.0
    for text, message in [("-MOTAA", "unknown metric 'MOTAA'"), ("abs(MOTA)", "unknown metric 'abs'"),
                          ("MOTA ** 2", "not allowed"), ("MOTA.real", "not allowed"), ("MOTA +", "expected arithmetic"), ("1 + 2", "names no metric"),
                          ("MOTA[nosuch]", "nosuch")]:
        with pytest.raises(ValueError, match=message):
            stress.Objective(text, "sort")
    with pytest.raises(RuntimeError, match="no HOTA"):
        stress.Objective("HOTA", "sort").value({"sort": {"HOTA": None}})


def test_the_search_finds_the_known_worst_corner_lowest_detection_probability():
    dims = [stress.dimension("sensor.pd=0.2:0.99"), stress.dimension("sensor.clutter_rate=0:2")]
    found = stress.search("sort", "clutter_storm", dims, "FN", budget=10, seed=0, config=SHORT)
    worst = found.worst(1)[0]
    assert not found.failed and len(found.scenes) == 10
    assert worst.params["sensor.pd"] < 0.4  # fewest detections, most misses
    assert worst.value == max(s.value for s in found.scenes) == found.worst_so_far()[-1]
    assert found.worst_so_far() == sorted(found.worst_so_far())


def test_one_seed_gives_one_search_whatever_the_workers_and_the_worst_reruns_from_its_toml(tmp_path):
    dims = [stress.dimension("groups.0.speed=0.5:3"), stress.dimension("render.camera=static|shake")]
    args = ("sort", "crossing", dims, "IDSW - MOTA", 4)
    one = stress.search(*args, seeds=[0, 1], seed=3, config=SHORT)
    two = stress.search(*args, seeds=[0, 1], seed=3, workers=2, config=SHORT)
    assert [(s.params, s.seed, s.value) for s in one.scenes] == [(s.params, s.seed, s.value) for s in two.scenes]
    other = stress.search(*args, seeds=[0, 1], seed=4, config=SHORT)
    assert [s.params for s in other.scenes] != [s.params for s in one.scenes]

    written = stress.write(one, tmp_path, 2)  # raises if a scene reruns to another value
    assert [w["value"] for w in written] == [s.value for s in one.worst(2)]
    for w, scene in zip(written, one.worst(2)):
        toml = tmp_path / w["scenario"].rsplit("/", 1)[1]
        assert scenario.load(toml) == scenario.load("crossing", {**SHORT, **scene.params})
        assert toml.with_suffix(".jpg").stat().st_size > 1000 and toml.with_suffix(".mp4").stat().st_size > 1000
        again = run_episode(str(toml), "sort", w["seed"])["metrics"]
        assert again["IDSW"] - again["MOTA"] == w["value"]
    assert (tmp_path / "history.png").is_file() and "| 1 |" in (tmp_path / "table.md").read_text()


def test_a_gap_objective_runs_both_trackers_on_the_same_world():
    dims = [stress.dimension("groups.0.speed=0.5:3")]
    found = stress.search("sort", "crossing", dims, "MOTA[sort] - MOTA[iou]", 2, config=SHORT)
    scene = found.worst(1)[0]
    assert set(scene.metrics) == {"sort", "iou"}
    config = {**SHORT, **scene.params}
    assert scene.value == (run_episode("crossing", "sort", scene.seed, config)["metrics"]["MOTA"]
                           - run_episode("crossing", "iou", scene.seed, config)["metrics"]["MOTA"])


def test_the_command_prints_json_worst_first_and_refuses_bad_keys(tmp_path, capsys):
    out = tmp_path / "found"
    assert cli.main(["stress", "sort", "--scenario", "crossing", "--vary", "groups.0.speed=0.5:3", "--budget", "3",
                     "--top", "2", "--out", str(out), "--json", "--config", "env.max_steps=30"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["evaluations"] == 3 and len(printed["worst"]) == 2
    first = printed["worst"][0]
    assert first["value"] >= printed["worst"][1]["value"] and first["value"] == printed["worst_so_far"][-1]
    assert cli.main(["run", first["scenario"], "--tracker", "sort", "--seed", str(first["seed"]), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["MOTA"] == -first["value"]

    for argv, message in [(["--vary", "sensor.pd=0:2"], "within the key's range"),
                          (["--vary", "render.camera=static|pan"], "needs a static or shaking camera"),
                          (["--vary", "groups.5.count=1:3"], "no such item"),
                          (["--vary", "sensor.pd=0:1", "--objective", "MOTA[sort] - MOTAX"], "unknown metric 'MOTAX'")]:
        assert exit_code(["stress", "sort", "--scenario", "crossing", *argv]) == 2
        assert message in capsys.readouterr().err


