"""Scenario files and overrides: loading, validation messages, presets, the reference table."""

import dataclasses

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from helpers import BOOKS_WITH_DECOY
from mtt_sim.sim import scenario
from mtt_sim.core.settings import ConfigError
from mtt_sim.core.validate import hints
from mtt_sim.sim.scenario import load


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
    ({"sensor.bogus": 1}, r"unknown key sensor\.bogus; allowed keys: model, preset, memory, pd"),
    ({"render.width": "wide"}, r"render\.width = 'wide': expected an integer"),
    ({"render.camera": "drone"}, r"render\.camera = 'drone': allowed values: 'static', 'pan', 'follow', 'shake'"),
    ({"world.walls": 1}, r"world\.walls = 1: expected true or false"),
    ({"groups.0.color": [1, 2]}, r"groups\.0\.color = \[1, 2\]: expected 3 values"),
    ({"groups.0.speed": float("nan")}, r"groups\.0\.speed = nan: expected a finite number"),
    ({"groups.5.speed": 1.0}, r"override groups\.5: no such item; groups has 2 entries"),
    ({"sensor.preset": "yolo"}, r"sensor\.preset = 'yolo': allowed values: 'ideal', 'dpm', 'frcnn', 'mot15_frcnn', 'sdp'"),
])
def test_bad_values_name_the_file_the_key_and_what_is_allowed(overrides, pattern):
    with pytest.raises(ConfigError, match=pattern) as err:
        load("crossing", overrides)
    assert "scenarios/crossing.toml" in str(err.value)


def test_cross_field_rules():
    with pytest.raises(ConfigError, match=r"groups\.2\.carrier = 'nobody': must name another group"):
        load(BOOKS_WITH_DECOY, {"groups.2.carrier": "nobody"})
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
            tp = hints(cls)[f.name]
            inner = getattr(tp, "__args__", (None,))[0]
            if dataclasses.is_dataclass(tp):
                yield from keys(tp, prefix + f.name + ".")
            elif dataclasses.is_dataclass(inner):
                yield from keys(inner, f"{prefix}{f.name}[].")
            else:
                yield prefix + f.name

    for key in keys(scenario.Scenario):
        assert f"| `{key}` |" in table


def test_mixed_override_forms_merge_and_a_value_given_twice_is_refused():
    sc = load("crossing", {"sensor.pd": 0.5, "sensor": {"clutter_rate": 3.0}})
    assert (sc.sensor.pd, sc.sensor.clutter_rate) == (0.5, 3.0)
    sc = load("crossing", {"sensor": {"clutter_rate": 3.0}, "sensor.pd": 0.5, "groups": {0: {"speed": 1.0}}})
    assert (sc.sensor.pd, sc.sensor.clutter_rate, sc.groups[0].speed) == (0.5, 3.0, 1.0)
    with pytest.raises(ConfigError, match=r"override sensor\.pd is given twice"):
        load("crossing", {"sensor.pd": 0.5, "sensor": {"pd": 0.6}})


def test_list_items_and_numpy_numbers_override():
    sc = load("crossing", {"groups.0.size": {"0": 5.0}, "sensor.pd": np.float32(0.5), "groups.0.count": np.int64(3),
                           "world.walls": np.bool_(True), "groups.0.color": np.array([1, 2, 3])})
    assert sc.groups[0].size[0] == 5.0 and sc.sensor.pd == 0.5 and sc.groups[0].count == 3 and sc.world.walls
    assert sc.groups[0].color == (1, 2, 3)
    with pytest.raises(ConfigError, match=r"groups\.0\.size\.0 = \{'a': 1\}: expected a finite number"):
        load("crossing", {"groups.0.size.0": {"a": 1}})


VALID_KEYS = ["sensor.pd", "sensor.clutter_rate", "render.width", "world.walls", "groups.0.count", "groups.0.size",
              "groups.0.size.1", "env.max_steps", "render.camera", "sensor", "groups.0", "groups", "world.size"]
VALUES = st.recursive(
    st.none() | st.booleans() | st.integers(-10**400, 10**400) | st.floats(allow_nan=True) | st.text(max_size=5)
    | st.sampled_from([np.float32(0.5), np.int64(3), np.bool_(False), np.array([1.0, 2.0])]),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.sampled_from(["pd", "0", "count", "x", 1]), inner,
                                                                  max_size=3),
    max_leaves=6)


@settings(max_examples=300, deadline=None)
@given(st.dictionaries(st.sampled_from(VALID_KEYS) | st.text(max_size=8) | st.integers(-2, 2), VALUES, max_size=4))
@example({"sensor.pd": np.float32(0.5), "sensor": {"clutter_rate": 3}, "groups.0.size": [10, 20.0],
          "world.walls": np.bool_(True)})  # loads: random overrides seldom do
@example({"groups.0.size": {"1": 7.0}, "groups": {0: {"count": np.int64(2)}}, "env.max_steps": 5})
def test_every_override_problem_is_a_config_error(overrides):
    """Any override either loads, and then the scenario holds every value asked for, or is a ConfigError (never
    another exception, never a value dropped or changed on the way)."""
    try:
        sc = load("crossing", overrides)
    except ConfigError:
        return
    loaded = scenario.to_mapping(sc)
    for key, value in overrides.items():
        node = loaded
        for part in str(key).split("."):
            node = _item(node, part)
        assert _holds(value, node), (key, value, node)


def _item(node, key):
    """A table's entry, or a list's item by its index."""
    return node[int(key)] if isinstance(node, list) else node[str(key)]


def _holds(asked, got) -> bool:
    """Whether a loaded value (plain tables and lists) is what an override asked for: each key of a table (a list's
    items by index), each item of a list, a number or string itself (an integer given for a float reads as equal)."""
    if isinstance(asked, (np.generic, np.ndarray)):
        asked = asked.tolist()
    if isinstance(asked, dict):
        return all(_holds(v, _item(got, k)) for k, v in asked.items())
    if isinstance(asked, (list, tuple)):
        return isinstance(got, list) and len(got) == len(asked) and all(map(_holds, asked, got))
    return got == asked


@settings(max_examples=100, deadline=None)
@given(pd=st.floats(0, 1), rate=st.floats(0, 100), dotted_first=st.booleans())
def test_no_override_value_is_ever_dropped(pd, rate, dotted_first):
    items = [("sensor.pd", pd), ("sensor", {"clutter_rate": rate})]
    sc = load("crossing", dict(items if dotted_first else items[::-1]))
    assert (sc.sensor.pd, sc.sensor.clutter_rate) == (pd, rate)


def test_totals_are_budgeted_before_anything_is_allocated():
    with pytest.raises(ConfigError, match=r"would need about 931\.\d GiB .* the budget is 4 GiB"):
        load("crossing", {"world.size": [100000, 100000]})
    groups = [{"name": f"g{i}", "count": 10000} for i in range(7)]
    with pytest.raises(ConfigError, match=r"70000 targets at reset; at most 65535 can be alive at once"):
        scenario.from_mapping({"groups": groups})
    with pytest.raises(ConfigError, match=r"world\.max_alive = 100000: out of range"):
        load("crossing", {"world.max_alive": 100000})
