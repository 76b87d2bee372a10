"""Scenario files and overrides: loading, validation messages, presets, the reference table."""

import dataclasses

import pytest

from mtt_sim import scenario
from mtt_sim.scenario import ConfigError, load


@pytest.mark.parametrize("key", sorted(scenario.available()))
def test_every_shipped_scenario_loads_and_round_trips(key):
    sc = load(key)
    assert sc.description and sc.name[0].isupper()
    assert scenario.from_mapping(scenario.to_mapping(sc)) == sc


def test_unknown_scenario_lists_the_available_ones():
    with pytest.raises(ConfigError, match=r"unknown scenario 'nope'; available: books, clutter_storm, crossing"):
        load("nope")


@pytest.mark.parametrize("overrides, pattern", [
    ({"sensor.pd": 1.5}, r"sensor\.pd = 1\.5: out of range; allowed: 0\.0 <= value <= 1\.0"),
    ({"sensor.bogus": 1}, r"unknown key sensor\.bogus; allowed keys: model, preset, pd"),
    ({"render.width": "wide"}, r"render\.width = 'wide': expected an integer"),
    ({"render.camera": "drone"}, r"render\.camera = 'drone': allowed values: 'static', 'pan', 'follow', 'shake'"),
    ({"world.walls": 1}, r"world\.walls = 1: expected true or false"),
    ({"groups.0.color": [1, 2]}, r"groups\.0\.color = \[1, 2\]: expected 3 values"),
    ({"groups.0.speed": float("nan")}, r"groups\.0\.speed = nan: expected a finite number"),
    ({"groups.5.speed": 1.0}, r"override groups\.5: no such item; groups has 2 entries"),
    ({"sensor.preset": "yolo"}, r"sensor\.preset = 'yolo': allowed values: 'ideal', 'dpm', 'frcnn', 'sdp'"),
])
def test_bad_values_name_the_file_the_key_and_what_is_allowed(overrides, pattern):
    with pytest.raises(ConfigError, match=pattern) as err:
        load("crossing", overrides)
    assert "scenarios/crossing.toml" in str(err.value)


def test_cross_field_rules():
    with pytest.raises(ConfigError, match=r"groups\.2\.carrier = 'nobody': must name another group"):
        load("books", {"groups.2.carrier": "nobody"})
    for camera in ("pan", "follow"):
        with pytest.raises(ConfigError, match=r"foreground' needs a static or shaking camera"):
            load("crossing", {"render.camera": camera})
    with pytest.raises(ConfigError, match=r"world\.size .* must be at least the image size"):
        load("crossing", {"world.size": [100.0, 100.0]})


def test_dotted_and_nested_overrides_are_the_same():
    assert load("crossing", {"sensor.clutter_rate": 5}) == load("crossing", {"sensor": {"clutter_rate": 5}})
    sc = load("books", {"groups.0.count": 2})
    assert (sc.groups[0].count, sc.groups[1].count) == (2, 1)


def test_preset_fills_keys_and_explicit_keys_win():
    sc = load("mot17_like")  # preset = "dpm"
    assert sc.sensor.box_scale == scenario.PRESETS["dpm"]["box_scale"]
    assert load("mot17_like", {"sensor.clutter_rate": 0.0}).sensor.clutter_rate == 0.0


def test_toml_file_path_loads(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('name = "Mine"\n[render]\nwidth = 64\nheight = 48\n')
    assert load(path).render.width == 64
    path.write_text("name = [")
    with pytest.raises(ConfigError, match="invalid TOML"):
        load(path)


def test_reference_table_documents_every_key():
    table = scenario.reference_table()

    def keys(cls, prefix=""):
        for f in dataclasses.fields(cls):
            tp = scenario._hints(cls)[f.name]
            inner = getattr(tp, "__args__", (None,))[0]
            if dataclasses.is_dataclass(tp):
                yield from keys(tp, prefix + f.name + ".")
            elif dataclasses.is_dataclass(inner):
                yield from keys(inner, f"{prefix}{f.name}[].")
            else:
                yield prefix + f.name

    for key in keys(scenario.Scenario):
        assert f"| `{key}` |" in table
